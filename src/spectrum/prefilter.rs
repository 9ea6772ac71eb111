//! Spectral prefiltering (issue 20): the RGB values an RGB render gives reflectances and a
//! fluorescent colorant, reduced under the scene's own light instead of D65.
//!
//! **Why.** An RGB render multiplies a light's colour by a material's colour channel by channel.
//! The material's RGB is the projection of its reflectance spectrum under D65
//! ([`super::measured::Measured::to_rgb`]), which is what the product means only for light whose
//! spectrum is close to D65's in each channel. Under a 532 nm laser the green channel of the light
//! is a line, and the reflectance that matters is `ρ(532)`, not `ρ`'s average over the broad
//! green band: the day-glo card's elastic reflectance is 0.09 at 532 nm and 0.29 projected under
//! D65, so the RGB render's green came out 33–88 % too strong (docs/fluorescence.md).
//!
//! **The prefilter** (G. Ward and E. Eydelberg-Vileshin, "Picture Perfect RGB Rendering Using
//! Spectral Prefiltering and Sharp Color Primaries", EGWR 2002, §3: each material's RGB is computed
//! under the scene's dominant illuminant and divided by the illuminant's RGB). Here the scene's
//! light is a sum of sources `S_i`, each weighted by `w_i` (what it brings to the scene: radiance
//! times the solid angle it subtends, chosen by the caller), and every spectrum's colour is the
//! one an RGB render carries for a light of that spectrum: `G(S)`, the linear Rec.709 colour
//! `M_XYZ→sRGB · XYZ(S)` with negative channels clamped to 0 and scaled back to `S`'s luminance
//! (a 532 nm laser is outside the sRGB gamut: clamping alone would make it 19 % brighter). The
//! scene's light is `e = Σ w_i G(S_i)` and a reflectance `ρ(λ)` becomes, per channel `k`,
//!
//! `ρ_k = Σ_i w_i G(ρ S_i)_k / e_k`,
//!
//! so that `ρ_k e_k` is the colour the reflected spectra have, channel by channel — exact for a
//! single source (a laser: `ρ_G = ρ(532)`) and a weighted mean of the sources' ratios otherwise. A
//! channel the scene's light does not reach (`e_k ≤ 10⁻⁶ max e`) keeps the D65 value given.
//!
//! **Fluorescence.** The colorant's 3 × 3 matrix `M` ([`super::fluorescence`]; A. Fichet, L.
//! Belcour and P. Barla, CGF 43(4), 2024) re-radiates each primary's illuminant spectrum exactly,
//! and a laser's line only approximately. With `o = Σ_i w_i G(R[S_i])` the colour of what the
//! colorant exactly re-emits under the scene's light (`R[S](λo) = ∫ K(λi → λo) S(λi) dλi`), the
//! rank-one correction
//!
//! `M' = M + (o − M e) eᵀ / (eᵀ e)`
//!
//! re-radiates the scene's light exactly (`M' e = o`) and leaves `M` as it was for colours
//! orthogonal to `e`. Entries are clamped to ≥ 0 (an RGB render carries non-negative channels);
//! the clamp can only act when `o − M e` has a negative channel and `e` more than one positive
//! channel. What no non-negative 3 × 3 matrix can do: tell the laser's green from the green in
//! the colorant's own orange. The orange light that meets the colorant again is re-excited as if
//! it were the laser's (in the spectrum it barely is: the dye does not absorb at 590 nm); a
//! correction that also maps the orange to its true re-emission needs negative entries.
//!
//! **The second tier.** A channel the scene's lights barely reach (below [`SECOND_TIER`] of the
//! brightest channel) is lit mostly by light that fluorescent colorants re-emit: under a green
//! laser, the red channel of the day-glo scene holds the card's orange. Such a channel is reduced
//! under the lights and the re-emitted spectra `R[S_i]` together (each as bright as the colorant
//! makes it): the card's elastic red is then its reflectance at the orange (0.83), not its D65
//! projection (clamped to 1), so light the card re-emits and meets again is not reflected too
//! strongly. Channels the lights do reach are not diluted by it.
//!
//! What a prefilter cannot do: a material lit by two lights of different spectra gets one RGB for
//! both (Ward & Eydelberg-Vileshin's "dominant illuminant" assumption). Spectral transport has no
//! such limit; `lapidary tradeoff` measures what the prefilter leaves.

use super::cie::{self, CIE_Y_INTEGRAL, CMF_SAMPLES, LAMBDA_MIN};
use super::fluorescence::Fluorescence;
use super::line::Line;
use super::measured::Measured;
use super::rgb2spec;
use crate::color::Rgb;
use glam::Vec3;

/// Channels of the scene's light below this fraction of its largest channel keep the D65 value.
pub const DARK_CHANNEL: f64 = 1e-6;

/// Channels of the scene's direct light below this fraction of its largest channel are reduced
/// under the light fluorescent colorants re-emit as well (module docs: the second tier).
pub const SECOND_TIER: f64 = 1e-2;

/// One emitter of the scene's light: its spectrum as quadrature nodes and its weight.
#[derive(Clone, Debug, PartialEq)]
pub struct Source {
    /// `(λ, S(λ) dλ)`, nm and radiance per node.
    nodes: Vec<(f32, f32)>,
    /// `w_i` per unit of the nodes' spectrum: the caller's weight divided by the spectrum's
    /// luminance, so that sources compare by the luminance the render gives them.
    weight: f64,
    /// Whether the spectrum is D65's (a grey RGB light or sky): a scene lit only by such sources
    /// needs no prefilter (the D65 projection is the prefilter).
    d65: bool,
}

impl Source {
    /// A narrow emission line (a laser's), weighted by `weight` (e.g. its luminance times the
    /// solid angle it subtends); `None` for a line without visible light or a weight ≤ 0.
    pub fn line(line: &Line, weight: f32) -> Option<Source> {
        Source::new(line.nodes().collect(), weight, false)
    }

    /// A measured emission spectrum (a lamp's), weighted like [`Source::line`].
    pub fn measured(spectrum: &Measured, weight: f32) -> Option<Source> {
        Source::new(grid(|l| spectrum.at(l)), weight, false)
    }

    /// An RGB light or sky colour, as the illuminant spectrum spectral renders give it
    /// ([`rgb2spec::illuminant`]: D65 for a grey), weighted like [`Source::line`].
    pub fn rgb(colour: Rgb, weight: f32) -> Option<Source> {
        let [r, g, b] = colour.0;
        let (scale, s) = rgb2spec::illuminant(colour.0);
        let d65 = r == g && g == b;
        Source::new(
            grid(|l| scale * s.eval(l) * rgb2spec::d65_normalised(l)),
            weight,
            d65,
        )
    }

    fn new(nodes: Vec<(f32, f32)>, weight: f32, d65: bool) -> Option<Source> {
        let y = f64::from(xyz(&nodes, |_| 1.0).y);
        (y > 0.0 && weight > 0.0 && weight.is_finite()).then(|| Source {
            nodes,
            weight: f64::from(weight) / y,
            d65,
        })
    }
}

/// The scene's light, for prefiltering an RGB render's materials (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Prefilter {
    sources: Vec<Source>,
    /// `e`, linear Rec.709.
    light: [f64; 3],
    /// What the scene's fluorescent colorants re-emit under `sources` (module docs: the second
    /// tier), and its colour.
    reemitted: Vec<Source>,
    reemitted_light: [f64; 3],
}

impl Prefilter {
    /// The prefilter for the scene's light made of `sources`; `None` when there is nothing to
    /// prefilter: no source, no light in any channel, or only D65 sources (grey lights and skies,
    /// for which the D65 projections are already right).
    pub fn new(sources: Vec<Source>) -> Option<Prefilter> {
        if sources.iter().all(|s| s.d65) {
            return None;
        }
        let light = weighted(&sources, |s| colour(xyz(&s.nodes, |_| 1.0)));
        (light.iter().any(|&v| v > 0.0)).then_some(Prefilter {
            sources,
            light,
            reemitted: vec![],
            reemitted_light: [0.0; 3],
        })
    }

    /// Adds what `colorant` re-emits under each source to the second tier: a source of the
    /// re-emitted spectrum `R[S_i]`, as bright as the colorant makes it (the weight per unit of
    /// `S_i`'s spectrum carries over).
    pub fn add_reemission(&mut self, colorant: &Fluorescence) {
        for s in &self.sources {
            let nodes = on_grid(&colorant.reemitted_spectrum(&s.nodes));
            if nodes.iter().any(|n| n.1 > 0.0) {
                self.reemitted.push(Source {
                    nodes,
                    weight: s.weight,
                    d65: false,
                });
            }
        }
        self.reemitted_light = weighted(&self.reemitted, |s| colour(xyz(&s.nodes, |_| 1.0)));
    }

    /// `e`: the scene's light as the render carries it (linear Rec.709, the sources' weights'
    /// units).
    pub fn light(&self) -> [f64; 3] {
        self.light
    }

    /// The RGB of the reflectance `rho` (a function of λ in nm, values 0 ..= 1) under the scene's
    /// light, each channel within 0 ..= 1; channels the light does not reach keep `d65`'s value
    /// (the D65 projection the material had).
    pub fn reflectance(&self, rho: impl Fn(f32) -> f32, d65: Rgb) -> Rgb {
        let reflected = weighted(&self.sources, |s| colour(xyz(&s.nodes, &rho)));
        let top = self.light.iter().fold(0.0f64, |a, &b| a.max(b));
        let second = (self.reemitted_light.iter().any(|&v| v > 0.0))
            .then(|| weighted(&self.reemitted, |s| colour(xyz(&s.nodes, &rho))));
        Rgb(std::array::from_fn(|k| {
            let (mut num, mut den) = (reflected[k], self.light[k]);
            if let Some(r) = &second
                && den <= SECOND_TIER * top
            {
                num += r[k];
                den += self.reemitted_light[k];
            }
            if den > DARK_CHANNEL * top {
                ((num / den) as f32).clamp(0.0, 1.0)
            } else {
                d65.0[k]
            }
        }))
    }

    /// `colorant`'s RGB matrix corrected by rank one so that it re-radiates the scene's light
    /// exactly (module docs), entries clamped to ≥ 0.
    pub fn fluorescence(&self, colorant: &Fluorescence) -> [[f32; 3]; 3] {
        let o = weighted(&self.sources, |s| colour(colorant.reemitted_xyz(&s.nodes)));
        let e = self.light;
        let m = colorant.rgb_matrix();
        let ee: f64 = e.iter().map(|v| v * v).sum();
        let r: [f64; 3] =
            std::array::from_fn(|i| o[i] - (0..3).map(|k| f64::from(m[i][k]) * e[k]).sum::<f64>());
        std::array::from_fn(|i| {
            std::array::from_fn(|k| ((f64::from(m[i][k]) + r[i] * e[k] / ee) as f32).max(0.0))
        })
    }
}

/// A spectrum on the 1 nm grid of [`cie::spectrum_to_xyz`] (value `i` at `360 + i` nm) as
/// quadrature nodes.
fn on_grid(values: &[f32]) -> Vec<(f32, f32)> {
    values
        .iter()
        .enumerate()
        .map(|(i, &v)| (LAMBDA_MIN + i as f32, v))
        .collect()
}

/// A spectrum on the 1 nm grid of [`cie::spectrum_to_xyz`] as quadrature nodes.
fn grid(f: impl Fn(f32) -> f32) -> Vec<(f32, f32)> {
    (0..CMF_SAMPLES)
        .map(|i| {
            let l = LAMBDA_MIN + i as f32;
            (l, f(l))
        })
        .collect()
}

/// XYZ of `Σ nodes · g` (normalised like [`cie::spectrum_to_xyz`]), in double precision.
fn xyz(nodes: &[(f32, f32)], g: impl Fn(f32) -> f32) -> Vec3 {
    let mut sum = [0.0f64; 3];
    for &(l, w) in nodes {
        let v = f64::from(w) * f64::from(g(l));
        for (s, b) in sum.iter_mut().zip(cie::xyz_bar(l).to_array()) {
            *s += v * f64::from(b);
        }
    }
    let n = f64::from(CIE_Y_INTEGRAL);
    Vec3::new(
        (sum[0] / n) as f32,
        (sum[1] / n) as f32,
        (sum[2] / n) as f32,
    )
}

/// `G`: linear Rec.709 of `xyz` with negative channels clamped to 0, scaled back to `xyz`'s
/// luminance (as a light's RGB colour is: [`crate::recipe`]'s stage resolution). Homogeneous of
/// degree 1, so a grey reflectance stays grey.
fn colour(xyz: Vec3) -> [f64; 3] {
    let c = cie::xyz_to_linear_srgb(xyz)
        .to_array()
        .map(|v| f64::from(v.max(0.0)));
    let (have, y) = (luminance(c), f64::from(xyz.y));
    if have > 0.0 && y > 0.0 {
        c.map(|v| v * y / have)
    } else {
        c
    }
}

fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// `Σ_i w_i f(S_i)`.
fn weighted(sources: &[Source], f: impl Fn(&Source) -> [f64; 3]) -> [f64; 3] {
    let mut sum = [0.0f64; 3];
    for s in sources {
        for (a, v) in sum.iter_mut().zip(f(s)) {
            *a += s.weight * v;
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;

    fn laser() -> Line {
        Line::new(532.0, 1.0)
    }

    /// A reflectance with a narrow dip at 532 nm (0.1 there, 0.8 elsewhere).
    fn dip(l: f32) -> f32 {
        0.8 - 0.7 * (-0.5 * ((l - 532.0) / 8.0).powi(2)).exp()
    }

    #[test]
    fn under_a_laser_the_green_channel_is_the_reflectance_at_the_line() {
        let p = Prefilter::new(vec![Source::line(&laser(), 1.0).unwrap()]).unwrap();
        let e = p.light();
        // A 532 nm line is saturated green: red and blue clamp to 0.
        assert!(e[1] > 0.0 && e[0] == 0.0 && e[2] == 0.0, "{e:?}");
        let d65 = Rgb::new(0.7, 0.5, 0.75);
        let rgb = p.reflectance(dip, d65);
        assert!((rgb.0[1] - dip(532.0)).abs() < 2e-3, "{rgb:?}");
        // The unlit channels keep the D65 values.
        assert_eq!((rgb.0[0], rgb.0[2]), (0.7, 0.75));
    }

    #[test]
    fn grey_reflectances_stay_grey_and_d65_light_needs_no_prefilter() {
        assert!(Prefilter::new(vec![Source::rgb(Rgb::splat(3.0), 2.0).unwrap()]).is_none());
        assert!(Prefilter::new(vec![]).is_none());
        let p = Prefilter::new(vec![
            Source::line(&laser(), 1.0).unwrap(),
            Source::rgb(Rgb::new(1.0, 0.3, 0.1), 0.5).unwrap(),
        ])
        .unwrap();
        let rgb = p.reflectance(|_| 0.4, Rgb::ZERO);
        for v in rgb.0 {
            assert!((v - 0.4).abs() < 1e-5, "{rgb:?}");
        }
    }

    #[test]
    fn two_sources_weigh_by_what_they_bring() {
        // A laser and an orange lamp: green mostly from the laser, red only from the lamp.
        let lamp = Rgb::new(1.0, 0.2, 0.0);
        let only_lamp = Prefilter::new(vec![Source::rgb(lamp, 1.0).unwrap()]).unwrap();
        let both = Prefilter::new(vec![
            Source::line(&laser(), 100.0).unwrap(),
            Source::rgb(lamp, 1.0).unwrap(),
        ])
        .unwrap();
        let (a, b) = (
            only_lamp.reflectance(dip, Rgb::ZERO),
            both.reflectance(dip, Rgb::ZERO),
        );
        // Red: the laser brings none, so both give the lamp's ratio.
        assert!((a.0[0] - b.0[0]).abs() < 1e-4, "{a:?} {b:?}");
        // Green: the laser dominates, pulling it toward ρ(532).
        assert!(
            (b.0[1] - dip(532.0)).abs() < 0.02 && a.0[1] > 0.5,
            "{a:?} {b:?}"
        );
    }

    /// A Gaussian spectrum on a 5 nm grid.
    fn gauss(mu: f32, sigma: f32, peak: f32) -> Measured {
        let pts: Vec<(f32, f32)> = (360..=830)
            .step_by(5)
            .map(|l| {
                let l = l as f32;
                (l, peak * (-0.5 * ((l - mu) / sigma).powi(2)).exp())
            })
            .collect();
        Measured::from_points(&pts, f32::MAX).unwrap()
    }

    #[test]
    fn the_corrected_matrix_reradiates_the_scene_light_exactly() {
        let dye =
            Fluorescence::new(&gauss(530.0, 25.0, 0.9), &gauss(590.0, 20.0, 1.0), 0.8).unwrap();
        for sources in [
            vec![Source::line(&laser(), 1.0).unwrap()],
            vec![
                Source::line(&laser(), 3.0).unwrap(),
                Source::rgb(Rgb::new(0.2, 0.5, 1.0), 1.0).unwrap(),
            ],
        ] {
            let p = Prefilter::new(sources.clone()).unwrap();
            let m = p.fluorescence(&dye);
            let e = p.light();
            let o = weighted(&sources, |s| colour(dye.reemitted_xyz(&s.nodes)));
            for i in 0..3 {
                let me: f64 = (0..3).map(|k| f64::from(m[i][k]) * e[k]).sum();
                assert!(
                    (me - o[i]).abs() <= 1e-5 * o.iter().fold(0.0f64, |a, &b| a.max(b)),
                    "row {i}: M'e {me} vs o {}",
                    o[i]
                );
            }
            // Colours orthogonal to e keep M's image.
            let old = dye.rgb_matrix();
            if e[0] == 0.0 && e[2] == 0.0 {
                for i in 0..3 {
                    assert_eq!((m[i][0], m[i][2]), (old[i][0], old[i][2]));
                }
            }
        }
    }

    #[test]
    fn a_channel_the_lights_miss_is_reduced_under_the_reemitted_light() {
        // Under a green laser the red channel holds only what the dye re-emits (orange): a
        // reflectance that is 0.5 in the orange and 1 elsewhere is 0.5 in red, not the D65 value.
        let dye =
            Fluorescence::new(&gauss(530.0, 25.0, 0.9), &gauss(590.0, 20.0, 1.0), 0.8).unwrap();
        let mut p = Prefilter::new(vec![Source::line(&laser(), 1.0).unwrap()]).unwrap();
        let rho = |l: f32| {
            if (550.0..650.0).contains(&l) {
                0.5
            } else {
                1.0
            }
        };
        let d65 = Rgb::new(0.9, 0.9, 0.9);
        assert_eq!(p.reflectance(rho, d65).0[0], 0.9);
        p.add_reemission(&dye);
        let rgb = p.reflectance(rho, d65);
        assert!((rgb.0[0] - 0.5).abs() < 0.01, "{rgb:?}");
        // Green, which the laser reaches, is the reflectance at 532 nm, undiluted.
        assert!((rgb.0[1] - 1.0).abs() < 1e-3, "{rgb:?}");
    }

    #[test]
    fn reemission_of_a_line_is_the_kernel_at_the_line() {
        // Under a narrow line at λi the re-emitted spectrum is K(λi → λo) times the line's area:
        // its luminance matches the 1 nm sum of the kernel.
        let flat = Measured::from_points(&[(360.0, 0.5), (830.0, 0.5)], 1.0).unwrap();
        // Zero below 590 nm (a measured spectrum extends its end values).
        let emission = Measured::from_points(
            &[(590.0, 0.0), (600.0, 1.0), (620.0, 1.0), (630.0, 0.0)],
            f32::MAX,
        )
        .unwrap();
        let dye = Fluorescence::new(&flat, &emission, 0.6).unwrap();
        let line = laser();
        let area: f32 = line.nodes().map(|(_, w)| w).sum();
        let got = dye.reemitted_xyz(&line.nodes().collect::<Vec<_>>()).y;
        let want = cie::spectrum_to_xyz(|lo| dye.kernel(532.0, lo) * area).y;
        assert!((got / want - 1.0).abs() < 1e-4, "{got} vs {want}");
    }
}
