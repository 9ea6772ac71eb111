#!/usr/bin/env python3
"""Writes the spectra of a day-glo (daylight-fluorescent) fire-orange colorant on card, for the
fluorescent Lambert base of a recipe (src/recipe/fluorescence.rs; the course scene of A. Wilkie
and A. Weidlich, layered-BRDF course 2009, section 5.2.2, figures 5.5/5.6: a 532 nm green laser
pointer on orange day-glo cardboard):

    data/spectra/dayglo-orange-excitation.csv  a(λ): fraction of incident photons the colorant absorbs
    data/spectra/dayglo-orange-emission.csv    e(λ): emission shape, peak 1
    data/spectra/dayglo-orange-substrate.csv   elastic reflectance of the card without the colorant

WHAT THESE ARE. NONE OF THE THREE FILES IS A MEASUREMENT. No measured spectrum of a day-glo
pigment, nor a licence-clear tabulated dye spectrum, could be reached offline (the machine
reaches only the cargo/pip/apt/npm registries, and no package found in their lists ships
rhodamine or day-glo spectra under an open licence: PhotochemCAD's tabulations declare no
licence, and the FPbase clients fetch over the network at run time). So every curve below is a PARAMETRIC FIT: sums of Gaussians in
wavenumber (cm^-1) placed at published peak positions. The widths, the relative weights
of the dyes, the UV band, the emission red shift, the optical-density scale and the substrate
level are MODELLING CHOICES, each flagged "choice" below. Only the peak positions, the molar
absorptivities and the quantum yields quoted are published numbers (taken from the sources
below as cited; the original papers were not re-read offline).

THE COLORANT. A daylight fluorescent pigment is a solid solution of fluorescent dyes, about
1-4 % by weight, in a transparent resin, usually a toluenesulfonamide-melamine-formaldehyde
resin, ground to a powder; the red-to-violet shades use rhodamines and the yellow shades
aminonaphthalimides and coumarins:
  [U] R. Ismael, H. Schwander, P. Hendrix, "Fluorescent Dyes and Pigments", Ullmann's
      Encyclopedia of Industrial Chemistry, Wiley-VCH 2013, ch. 13 "Daylight Fluorescent Pigments".
  [R] P. J. Ryan, "Daylight fluorescent pigments and colours", Pigment & Resin Technology 1(9),
      21-26 (1972), doi:10.1108/eb040844 (1-4 % dye, molecularly dissolved in a resin).
  [T] text on daylight fluorescent pigments at kraska.biz/chemistry/pearlescent-pigments (a
      secondary page): toluenesulfonamide-melamine-formaldehyde matrix; rhodamines for the
      red-to-violet shades, aminonaphthalimides and coumarins for the yellows.
Fire / blaze orange is modelled as rhodamine 6G (C.I. Basic Red 1) + rhodamine B (C.I. Basic
Violet 10) + a yellow coumarin-type dye, with cascade energy transfer yellow -> R6G -> RB so that
the emission comes from the longest-wavelength absorber (Connors-Rowe et al. [W] found energy
transfer between the two dyes of their orange/red/gold daylight-fluorescent watercolours).
The dye mix is a choice: pigment makers do not publish formulations.

PUBLISHED NUMBERS USED
  Rhodamine 6G in ethanol: absorption maximum 530 nm (529.75 nm), molar absorptivity
      116,000 M^-1 cm^-1, vibronic shoulder near 500 nm; fluorescence maximum ~552 nm.
      [D] H. Du, R. A. Fuh, J. Li, L. A. Corkan, J. S. Lindsey, "PhotochemCAD: A computer-aided
      design and research tool in photochemistry", Photochem. Photobiol. 68, 141-142 (1998);
      M. Taniguchi, J. S. Lindsey, "Database of absorption and fluorescence spectra of >300
      common compounds for use in PhotochemCAD", Photochem. Photobiol. 94, 290-327 (2018);
      as tabulated by S. Prahl, omlc.org/spectra/PhotochemCAD (R6G and RB pages).
  Rhodamine B in ethanol: absorption maximum 543 nm (542.75 nm), 106,000 M^-1 cm^-1, shoulder
      near 515 nm; fluorescence maximum ~565-570 nm [D].
  Quantum yields: R6G 0.95 in ethanol:
      [K] R. F. Kubin, A. N. Fletcher, "Fluorescence quantum yields of some rhodamine dyes",
      J. Luminescence 27, 455-462 (1982); confirmed by thermal lens, 0.95:
      [F] M. Fischer, J. Georges, Chem. Phys. Lett. 260, 115-118 (1996).
      R6G in a HEMA:MMA copolymer (a solid polymer host, low concentration): 0.94,
      [H] W. Holzer et al., Chem. Phys. 256, 125-136 (2000), doi:10.1016/S0301-0104(00)00101-4.
      RB: 0.65 in basic ethanol [K]; 0.49-0.70 in neutral ethanol across studies
      (M. J. Snare et al., J. Photochem. 18, 335 (1982): 0.49; K. G. Casey, E. L. Quitevis,
      J. Phys. Chem. 92, 6590 (1988): 0.70) -- as compiled on the OMLC rhodamine B page.
      Concentration quenching of R6G in PMMA: [P] A. Kurian et al., Laser Chemistry 20, 99-110
      (2002), doi:10.1155/2002/427269 (yield falls as the dye loading rises).
  Blaze / hunter orange: daylight-fluorescent orange of dominant wavelength 595-605 nm,
      luminance factor >= 40 %, excitation purity >= 85 % (International Hunter Education
      Association definition, as quoted in US state hunting regulations).
  Fluorescent pigments absorb in the near-UV, blue and green and re-emit in a narrow band;
      a fluorescent red-orange turns yellow-green light into red-orange:
      [HD] D. R. Hanson, A. D. Dickson (3M), "Significant visual properties of some fluorescent
      pigments", Highway Research Record 49, 13-29 (1964); TRB record 168277 (Symposium on
      Conspicuity on the Highway, St. Paul 1980).
  [W] S. A. Connors-Rowe, H. R. Morris, P. M. Whitmore, "Evaluation of appearance and fading of
      daylight fluorescent watercolors", JAIC 44(2), 75-94 (2005): hue shifts at high
      concentration from a widened absorption band, self-absorption and two-dye energy transfer.
  Course / model: A. Wilkie, A. Weidlich, C. Larboulette, W. Purgathofer, "A reflectance model
      for diffuse fluorescent surfaces", GRAPHITE 2006 (ref. [39] of the course).

THE FIT
  Optical density OD(λ) = sum of Gaussians in wavenumber, exp(-4 ln2 (ν - ν0)² / FWHM²):
    R6G   main 530 nm [D], FWHM 1150 cm^-1 (choice: ~32 nm, the ethanol band's main peak);
          0-1 vibronic shoulder +1200 cm^-1 (~498 nm) [D: shoulder near 500 nm], 0.33 of main,
          FWHM 1600 cm^-1 (choice).
    RB    main 543 nm [D], FWHM 1150 cm^-1 (choice); shoulder +1150 cm^-1 (~511 nm) [D], 0.33,
          FWHM 1600 cm^-1 (choice).
    R6G and RB in equal weight (choice).
    Rhodamine S0->S2 band at 350 nm, 0.12 of each rhodamine's main band, FWHM 3500 cm^-1
          (choice; the weak near-UV band of xanthene dyes, visible in [D]).
    Yellow coumarin-type dye: one broad band at 440 nm, FWHM 3500 cm^-1 (~68 nm), 0.9 of the
          rhodamines' joint peak (choice; coumarin yellows absorb at ~430-460 nm, e.g. coumarin 6 at
          459 nm in ethanol [D]; the weight is set so the card absorbs 70-90 % from 420 to 560 nm
          and looks orange, not pink: a fire orange reflects little blue [HD]).
  No solvent-to-resin shift is applied (choice: none is published for this resin).
  OD is scaled so its maximum is 1.0, and a(λ) = 1 - 10^(-OD(λ)): the colorant layer absorbs
  90 % of the photons at its peak (ASSUMPTION: an optically thick pigment layer of single-pass
  optical density 1 at the peak; the 10^-OD form saturates the top as a thick layer does).
  a(532 nm) = 0.899, a(450 nm) = 0.85, a(580 nm) = 0.07, a(600 nm) = 0.002, a(610 nm) = 5e-4,
  a < 1e-4 above ~622 nm; values below 1e-6 are written as 0. Not modelled: the optical brighteners some day-glo pigments
  also contain (L. Reiß, T. Prestel, S. Giering, Heritage Science 10 (2022),
  doi:10.1186/s40494-022-00812-4), so the near-UV absorption (a ~ 0.2 at 360-380 nm, 0.47 at
  400 nm, from the rhodamines' S2 band and the yellow's tail) is probably low.

  Emission e(λ): the emitter is rhodamine B at the end of the energy-transfer cascade [W]. Its
  ethanol emission peaks at ~565-570 nm [D]; in a concentrated, optically thick pigment layer the
  short-wavelength side is reabsorbed and the band shifts red [W], and the blaze-orange
  definition puts the dominant wavelength at 595-605 nm. Fit: main Gaussian at 590 nm (choice
  within 580-600 nm), FWHM 1300 cm^-1 (~45 nm; choice, a little wider than RB's ethanol band),
  vibronic shoulder at -1200 cm^-1 (~634 nm), 0.30 of main, FWHM 1600 cm^-1 (choice; mirror
  image of the absorption shoulder). The sum peaks at 592 nm, FWHM 54 nm; e < 0.01 below
  ~537 nm, < 1e-3 below ~527 nm (0.02 % of the photons lie below 532 nm, which the renderer's
  Stokes rule drops for the laser); values below 1e-6 are written as 0; peak 1.

  Quantum yield (for the recipe, not a file): 0.7. Reason: the emitter is RB, whose yield is
  0.49-0.70 in ethanol (Snare et al.; Casey & Quitevis) and 0.65 in basic
  ethanol [K]; a rigid polar resin raises it (in the
  solid copolymer of [H] R6G keeps 0.94), while the 1-4 % dye loading of a pigment [R] quenches
  (concentration quenching [P]) and the cascade loses a little at each transfer. 0.7 sits
  between the dilute-solution and the quenched values; it is a CHOICE, not a measured
  yield of a day-glo pigment (none was found).

  Substrate: the card and the colourless resin without the dyes, FLAT 0.85 from 360 to 830 nm
  (ASSUMPTION: a white, diffusely reflecting paperboard; the real card's near-UV drop and
  any optical brightener are not modelled).

Usage:
    scripts/dayglo-spectra.py            # write the three CSVs and print the figures
    scripts/dayglo-spectra.py --out-dir /tmp/x

Python 3 standard library only.
"""

import argparse
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT_DIR = os.path.join(ROOT, "data", "spectra")

GRID = list(range(360, 831, 2))  # output wavelengths, nm (236 points)
FINE = [360 + 0.1 * i for i in range(4701)]  # for peak and FWHM read-outs

# --- absorption (optical density) model: (peak nm, FWHM cm^-1, weight) ---------------------
R6G_PEAK_NM = 530.0  # [D] 529.75 nm in ethanol
RB_PEAK_NM = 543.0  # [D] 542.75 nm in ethanol
MAIN_FWHM = 1150.0  # choice
SHOULDER_FWHM = 1600.0  # choice
R6G_SHOULDER_SHIFT = 1200.0  # cm^-1 above the main band: ~498 nm [D: shoulder near 500 nm]
RB_SHOULDER_SHIFT = 1150.0  # cm^-1: ~511 nm [D: shoulder near 515 nm]
SHOULDER_WEIGHT = 0.33  # choice
R6G_WEIGHT = 1.0  # choice: equal parts R6G and RB
RB_WEIGHT = 1.0
S2_PEAK_NM = 350.0  # choice: xanthene S0->S2 band
S2_FWHM = 3500.0
S2_WEIGHT = 0.12  # of each rhodamine's main band
YELLOW_PEAK_NM = 440.0  # choice: coumarin-type yellow (coumarin 6: 459 nm [D])
YELLOW_FWHM = 3500.0
YELLOW_WEIGHT = 0.9  # relative to the rhodamines' joint peak
PEAK_OD = 1.0  # assumption: a(peak) = 1 - 10^-1 = 0.9

# --- emission model ----------------------------------------------------------------------
EM_PEAK_NM = 590.0  # choice in 580-600 nm (RB ~567 nm in ethanol [D], red-shifted in the layer)
EM_FWHM = 1300.0  # choice
EM_SHOULDER_SHIFT = 1200.0  # cm^-1 below the main band
EM_SHOULDER_WEIGHT = 0.30
EM_SHOULDER_FWHM = 1600.0

QUANTUM_YIELD = 0.7  # choice, see the docstring
SUBSTRATE = 0.85  # assumption, flat
FLOOR = 1e-6  # values below are written as 0


def wn(lam_nm):
    return 1e7 / lam_nm


def band(lam_nm, peak_nm, fwhm_wn, shift_wn=0.0):
    """A Gaussian in wavenumber, peak 1, centred at wn(peak_nm) + shift_wn."""
    d = wn(lam_nm) - (wn(peak_nm) + shift_wn)
    return math.exp(-4.0 * math.log(2.0) * d * d / (fwhm_wn * fwhm_wn))


def rhodamine(lam, peak, shoulder_shift):
    return (
        band(lam, peak, MAIN_FWHM)
        + SHOULDER_WEIGHT * band(lam, peak, SHOULDER_FWHM, shoulder_shift)
        + S2_WEIGHT * band(lam, S2_PEAK_NM, S2_FWHM)
    )


def od_raw(lam):
    return R6G_WEIGHT * rhodamine(lam, R6G_PEAK_NM, R6G_SHOULDER_SHIFT) + RB_WEIGHT * rhodamine(
        lam, RB_PEAK_NM, RB_SHOULDER_SHIFT
    )


RHOD_MAX = max(od_raw(l) for l in FINE)


def od_unscaled(lam):
    """Rhodamines normalised to 1 at their joint peak, plus the yellow dye."""
    return od_raw(lam) / RHOD_MAX + YELLOW_WEIGHT * band(lam, YELLOW_PEAK_NM, YELLOW_FWHM)


OD_MAX = max(od_unscaled(l) for l in FINE)


def od(lam):
    """Optical density of the colorant layer, maximum PEAK_OD."""
    return PEAK_OD * od_unscaled(lam) / OD_MAX


def excitation(lam):
    return 1.0 - 10.0 ** (-od(lam))


def emission(lam):
    return band(lam, EM_PEAK_NM, EM_FWHM) + EM_SHOULDER_WEIGHT * band(
        lam, EM_PEAK_NM, EM_SHOULDER_FWHM, -EM_SHOULDER_SHIFT
    )


EM_MAX = max(emission(l) for l in FINE)


def emission_norm(lam):
    return emission(lam) / EM_MAX


def substrate(_lam):
    return SUBSTRATE


def peak_and_fwhm(f):
    vals = [f(l) for l in FINE]
    i = max(range(len(vals)), key=vals.__getitem__)
    half = vals[i] / 2.0
    lo = i
    while lo > 0 and vals[lo] > half:
        lo -= 1
    hi = i
    while hi < len(vals) - 1 and vals[hi] > half:
        hi += 1
    return FINE[i], vals[i], FINE[hi] - FINE[lo]


def fmt(v):
    return "0" if v < FLOOR else f"{v:.6f}".rstrip("0").rstrip(".")


def write(path, header, f):
    lines = ["# " + h if h else "#" for h in header]
    lines.append("wavelength_nm,value")
    lines += [f"{l},{fmt(f(l))}" for l in GRID]
    text = "\n".join(lines) + "\n"
    with open(path, "w", encoding="utf-8") as out:
        out.write(text)
    return text


COMMON = [
    "DERIVED PARAMETRIC FIT, NOT A MEASUREMENT. Written by scripts/dayglo-spectra.py, whose docstring cites every number",
    "and marks each modelling choice. Day-glo fire orange = rhodamine 6G + rhodamine B + a yellow coumarin-type dye in",
    "a melamine-formaldehyde-type resin (Ullmann's Encyclopedia, Fluorescent Dyes and Pigments, ch. 13, Wiley-VCH 2013;",
    "P. J. Ryan, Pigment & Resin Technology 1(9) 21 (1972)). Peak positions: H. Du et al., Photochem. Photobiol. 68, 141",
    "(1998) and M. Taniguchi & J. S. Lindsey, Photochem. Photobiol. 94, 290 (2018) (PhotochemCAD), R6G 530 nm, RB 543 nm",
    "in ethanol. Gaussians in wavenumber; widths and weights are choices. Scene: Wilkie & Weidlich layered-BRDF course",
    "2009, section 5.2.2 (532 nm laser on day-glo orange card). Suggested quantum_yield 0.7 (choice; R6G 0.95 in ethanol,",
    "Kubin & Fletcher, J. Lumin. 27, 455 (1982); RB 0.49-0.70 in ethanol).",
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out-dir", default=OUT_DIR)
    args = ap.parse_args()
    os.makedirs(args.out_dir, exist_ok=True)

    a_pk, a_max, _ = peak_and_fwhm(excitation)
    od_pk, _, od_fw = peak_and_fwhm(od)
    e_pk, _, e_fw = peak_and_fwhm(emission_norm)
    a532 = excitation(532.0)
    edge = next(l for l in FINE if l > a_pk and excitation(l) < 0.01)
    e_lo = next(l for l in FINE if emission_norm(l) > 0.01)
    total = sum(emission_norm(l) for l in FINE)
    above532 = sum(emission_norm(l) for l in FINE if l >= 532.0) / total

    files = {
        "dayglo-orange-excitation.csv": (
            COMMON
            + [
                "Column value: a(lambda), the FRACTION (0..1) of incident photons the fluorescent colorant layer absorbs.",
                "a = 1 - 10^(-OD), OD scaled to 1.0 at its maximum: ASSUMPTION of an optically thick pigment layer absorbing 90 % at",
                f"the peak. OD peak {od_pk:.1f} nm (FWHM {od_fw:.1f} nm); a peak {a_max:.3f} at {a_pk:.1f} nm; a(532 nm) = {a532:.3f};",
                f"a < 0.01 above {edge:.0f} nm; values below 1e-6 written as 0.",
            ],
            excitation,
        ),
        "dayglo-orange-emission.csv": (
            COMMON
            + [
                "Column value: e(lambda), emission SHAPE, peak 1 (the renderer normalises it). Emitter: rhodamine B at the end of",
                "the yellow -> R6G -> RB energy-transfer cascade; RB emits at ~565-570 nm in ethanol (PhotochemCAD), red-shifted in a",
                "concentrated layer (Connors-Rowe, Morris & Whitmore, JAIC 44(2) 75 (2005)); blaze orange has a dominant wavelength",
                f"of 595-605 nm. Fit peak {e_pk:.1f} nm (choice in 580-600 nm), FWHM {e_fw:.1f} nm; e < 0.01 below {e_lo:.0f} nm;",
                "values below 1e-6 written as 0.",
            ],
            emission_norm,
        ),
        "dayglo-orange-substrate.csv": (
            [
                "Elastic reflectance of the card and colourless resin WITHOUT the fluorescent colorant's absorption (the base's",
                "albedo; the renderer reflects albedo * (1 - a)). FLAT 0.85 from 360 to 830 nm: an ASSUMPTION (white diffuse",
                "paperboard), not a measurement; the near-UV drop of real card and optical brighteners are not modelled.",
                "Written by scripts/dayglo-spectra.py.",
            ],
            substrate,
        ),
    }
    for name, (header, f) in files.items():
        path = os.path.join(args.out_dir, name)
        text = write(path, header, f)
        check(path, text, name != "dayglo-orange-emission.csv")

    half = [l for l in FINE if excitation(l) >= a_max / 2]
    print(f"excitation a: peak {a_max:.3f} at {a_pk:.1f} nm, a >= half of it from {half[0]:.1f} to {half[-1]:.1f} nm "
          f"(saturated); OD peak {od_pk:.1f} nm, OD FWHM {od_fw:.1f} nm")
    print(f"  a(532) = {a532:.3f}; a(450) = {excitation(450):.3f}; a(580) = {excitation(580):.3f}; "
          f"a(600) = {excitation(600):.4f}; a(610) = {excitation(610):.5f}; a < 0.01 above {edge:.1f} nm")
    print(f"emission e: peak {e_pk:.1f} nm, FWHM {e_fw:.1f} nm; e < 0.01 below {e_lo:.1f} nm; "
          f"fraction of photons at >= 532 nm: {above532:.4f}")
    print(f"quantum yield (recipe): {QUANTUM_YIELD}; substrate: flat {SUBSTRATE}")


def check(path, text, unit_range):
    rows = [l for l in text.splitlines() if l and not l.startswith("#")][1:]
    pts = [tuple(float(x) for x in r.split(",")) for r in rows]
    assert 2 <= len(pts) <= 4096, path
    assert len(text.encode()) < 1 << 20, path
    assert all(b[0] > a[0] for a, b in zip(pts, pts[1:])), path
    assert all(math.isfinite(v) and v >= 0.0 for _, v in pts), path
    if unit_range:
        assert all(v <= 1.0 for _, v in pts), path
    else:
        assert max(v for _, v in pts) <= 1.0 + 1e-9, path


if __name__ == "__main__":
    sys.exit(main())
