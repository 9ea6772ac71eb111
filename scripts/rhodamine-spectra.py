#!/usr/bin/env python3
"""Writes a fluorescent colorant from MEASURED rhodamine 6G spectra, for the fluorescent Lambert
base of a recipe (src/recipe/fluorescence.rs; materials/fluorescent.ron "rhodamine6g_card"):

    data/spectra/rhodamine6g-excitation.csv  a(λ): fraction of incident photons the dye layer absorbs
    data/spectra/rhodamine6g-emission.csv    e(λ): emission shape, peak 1

THE MEASUREMENTS (shipped unchanged next to the outputs, with their provenance in their headers):

    data/spectra/rhodamine6g-absorption-nyman2017.csv  absorption cross-section, m², 399-700 nm
    data/spectra/rhodamine6g-emission-nyman2017.csv    fluorescence emission, counts, 480.8-691.8 nm

    R. A. Nyman (2017), "Absorption and Fluorescence spectra of Rhodamine 6G", Zenodo,
    doi:10.5281/zenodo.569817 (CC BY 4.0); rhodamine 6G in ethylene glycol, as combined and
    cleaned by its authors in github.com/photonbec/PyPBEC (MIT), commit 8080b62, files
    PyPBEC/data/{absorption_cross_sections,fluorescence_spectrum}_R6G_in_EthyleneGlycol_corrected.csv.

Rhodamine 6G (C.I. Basic Red 1) is one of the dyes of daylight-fluorescent (day-glo) pigments
(Ullmann's Encyclopedia, "Fluorescent Dyes and Pigments", ch. 13; see scripts/dayglo-spectra.py).

WHAT THIS SCRIPT DOES TO THEM (each step a choice, named here):
  Excitation: a(λ) = 1 − 10^(−OD · σ(λ)/σ_max), the fraction a dye layer of optical density OD at
      the absorption peak absorbs (Beer–Lambert), with OD = 1 (CHOICE, as for the day-glo fit:
      a(peak) = 0.9). σ is linear between the measured 1 nm points; values the authors publish
      below zero (noise beyond ~632 nm) are taken as 0; 0 outside 399-700 nm. The absolute
      scale of σ, which the authors distrust, cancels.
  Emission: the detector's dark floor is subtracted (CHOICE: the median of the counts from 481
      to 495 nm, where rhodamine 6G does not emit, and below which the file has no data),
      values below 0 are set to 0, the four gaps the authors cut out (room-light spikes) are
      bridged linearly, and the spectrum is 0 outside 481-691 nm; peak normalised to 1. No
      spectrometer-response correction is documented for the measurement, and none is applied.
  Quantum yield (for the recipe, not a file): 0.95, rhodamine 6G's in ethanol (R. F. Kubin and
      A. N. Fletcher, J. Luminescence 27, 455-462, 1982), 0.94 in a solid HEMA:MMA copolymer
      (W. Holzer et al., Chem. Phys. 256, 125-136, 2000).

The dye in solution emits at 558 nm (yellow-green): a day-glo ORANGE also needs rhodamine B and
the red shift of a concentrated layer, for which no measurement is available here, so the
course scenes keep the fitted fire-orange colorant of scripts/dayglo-spectra.py.

Usage:
    scripts/rhodamine-spectra.py            # write the two CSVs and print the figures
    scripts/rhodamine-spectra.py --out-dir /tmp/x

Python 3 standard library only.
"""

import argparse
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SPECTRA = os.path.join(ROOT, "data", "spectra")
OD = 1.0  # choice: optical density of the dye layer at the absorption peak
GRID = list(range(360, 831))  # output wavelengths, nm


def read(path):
    rows = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#") or line.startswith("wavelength"):
                continue
            a, b = line.split(",")
            rows.append((float(a), float(b)))
    rows.sort()
    return rows


def lerp(rows, x):
    """Linear interpolation in `rows` (sorted), 0 outside."""
    if x < rows[0][0] or x > rows[-1][0]:
        return 0.0
    lo, hi = 0, len(rows) - 1
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if rows[mid][0] <= x:
            lo = mid
        else:
            hi = mid
    (x0, y0), (x1, y1) = rows[lo], rows[hi]
    return y0 if x1 == x0 else y0 + (y1 - y0) * (x - x0) / (x1 - x0)


def write(path, header, values):
    with open(path, "w", encoding="utf-8") as f:
        for h in header:
            f.write(f"# {h}\n")
        f.write("wavelength_nm,value\n")
        for lam, v in zip(GRID, values):
            f.write(f"{lam},{v:.6g}\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out-dir", default=SPECTRA)
    args = ap.parse_args()
    sigma = [(l, max(v, 0.0)) for l, v in read(os.path.join(SPECTRA, "rhodamine6g-absorption-nyman2017.csv"))]
    smax = max(v for _, v in sigma)
    peak_sigma = max(sigma, key=lambda r: r[1])[0]
    a = [1.0 - 10.0 ** (-OD * lerp(sigma, l) / smax) for l in GRID]
    counts = read(os.path.join(SPECTRA, "rhodamine6g-emission-nyman2017.csv"))
    floor = sorted(v for l, v in counts if 481.0 <= l <= 495.0)
    floor = floor[len(floor) // 2]
    em = [max(lerp(counts, l) - floor, 0.0) for l in GRID]
    emax = max(em)
    em = [v / emax for v in em]
    os.makedirs(args.out_dir, exist_ok=True)
    src = "R. A. Nyman (2017), Zenodo doi:10.5281/zenodo.569817 (CC BY 4.0), rhodamine 6G in ethylene glycol"
    write(
        os.path.join(args.out_dir, "rhodamine6g-excitation.csv"),
        [
            "Rhodamine 6G: fraction of incident photons a dye layer of optical density 1 at the peak absorbs,",
            "a = 1 - 10^(-sigma/sigma_max), from the MEASURED cross-section sigma of " + src + ".",
            "Written by scripts/rhodamine-spectra.py (its docstring names every processing choice).",
        ],
        a,
    )
    write(
        os.path.join(args.out_dir, "rhodamine6g-emission.csv"),
        [
            "Rhodamine 6G: fluorescence emission shape, peak 1, from the MEASURED spectrum of " + src + ",",
            f"dark floor ({floor:.1f} counts) subtracted, gaps bridged linearly, 0 outside 481-691 nm.",
            "Written by scripts/rhodamine-spectra.py (its docstring names every processing choice).",
        ],
        em,
    )
    peak_em = GRID[max(range(len(GRID)), key=lambda i: em[i])]
    half = [GRID[i] for i in range(len(GRID)) if em[i] >= 0.5]
    print(f"absorption peak {peak_sigma:.0f} nm; a(532) = {a[532 - 360]:.3f}, a(500) = {a[500 - 360]:.3f}, a(580) = {a[580 - 360]:.4f}")
    print(f"emission peak {peak_em} nm, half maximum {half[0]}-{half[-1]} nm, dark floor {floor:.1f} counts of {emax + floor:.0f}")


if __name__ == "__main__":
    main()
