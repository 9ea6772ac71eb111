#!/usr/bin/env python3
"""Derives the body absorption spectrum of red Oregon sunstone (labradorite coloured by colloidal
metallic copper) and writes data/spectra/oregon-sunstone-cu-colloid.csv, for a body's
`medium.absorption_spectrum` (docs/recipes.md).

This is a DERIVED spectrum, not a measurement: no digitised transmission spectrum of Oregon
sunstone is reachable offline (docs/spectral.md). A powder or diffuse-reflectance spectrum (USGS
splib07 and the like) would not be a body colour either, so none is substituted.

Physics: quasi-static (dipole) absorption of small copper particles embedded in a non-absorbing
host of refractive index n_m (Bohren & Huffman 1983, eq. 5.32; Kreibig & Vollmer 1995). For a
volume fraction f of spheres the absorption coefficient is

    alpha(λ) = f · C_abs / V = f · 3 (2π n_m / λ) · Im[(ε − ε_m) / (ε + 2 ε_m)],

ε = (n + i k)² of copper (Johnson & Christy 1972, data/metals/copper.csv, n and k interpolated
linearly in wavelength), ε_m = n_m². With --aspect the particles are randomly oriented prolate
spheroids: 3 / (ε + 2ε_m) becomes the orientation mean of 1 / (ε_m + L_j (ε − ε_m)) over the three
depolarisation factors L_j (Bohren & Huffman §5.3). With --radius-nm the free-electron (Drude)
part of ε gets Kreibig's mean-free-path damping γ(r) = γ_bulk + A v_F / r, i.e.
ε → ε + ω_p² / (ω² + i ω γ_bulk) − ω_p² / (ω² + i ω γ(r)) (ħω_p = 8.8 eV, ħγ_bulk = 0.0955 eV,
v_F = 1.57e6 m/s, A = 1); off by default because A for copper in feldspar is not pinned down.

The file is normalised to its maximum over 360–830 nm (the recipe scales it to a body's
absorption per object unit); f only scales it, so it drops out.

Usage:
    scripts/sunstone-spectrum.py                  # write the CSV, print the figures
    scripts/sunstone-spectrum.py --table          # also: band peak against spheroid aspect ratio
    scripts/sunstone-spectrum.py --radius-nm 5 --aspect 1.3 --out /tmp/x.csv   # variants

Python 3 standard library only.
"""

import argparse
import cmath
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
COPPER = os.path.join(ROOT, "data", "metals", "copper.csv")
OUT = os.path.join(ROOT, "data", "spectra", "oregon-sunstone-cu-colloid.csv")

HOST_INDEX = 1.565  # labradorite (An~70), mean of the principal indices; birefringence ~0.01 ignored
HC_EV_NM = 1239.84198  # h c in eV nm
HBAR_EV_S = 6.582119569e-16
CU_PLASMA_EV = 8.8  # ħω_p of copper's free electrons
CU_GAMMA_BULK_EV = 0.0955  # ħ/τ, τ = 6.9 fs (Johnson & Christy 1972)
CU_FERMI_VELOCITY = 1.57e6  # m/s
KREIBIG_A = 1.0
CU_DENSITY = 8.96  # g/cm³
LABRADORITE_DENSITY = 2.70  # g/cm³

GRID = list(range(360, 831, 5))  # output wavelengths, nm


def read_copper(path=COPPER):
    rows = []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#") or line.startswith("wavelength"):
                continue
            lam, n, k = (float(x) for x in line.split(","))
            rows.append((lam, n, k))
    if any(b[0] <= a[0] for a, b in zip(rows, rows[1:])):
        sys.exit(f"{path}: wavelengths not increasing")
    return rows


def nk_at(rows, lam):
    """n and k linearly interpolated in wavelength (no extrapolation)."""
    if not rows[0][0] <= lam <= rows[-1][0]:
        raise ValueError(f"{lam} nm outside the copper table")
    for (l0, n0, k0), (l1, n1, k1) in zip(rows, rows[1:]):
        if lam <= l1:
            t = (lam - l0) / (l1 - l0)
            return n0 + t * (n1 - n0), k0 + t * (k1 - k0)
    raise AssertionError


def copper_eps(rows, lam, radius_nm=None):
    n, k = nk_at(rows, lam)
    eps = complex(n, k) ** 2
    if radius_nm:
        w = HC_EV_NM / lam
        g_r = CU_GAMMA_BULK_EV + KREIBIG_A * HBAR_EV_S * CU_FERMI_VELOCITY / (radius_nm * 1e-9)
        wp2 = CU_PLASMA_EV**2
        eps += wp2 / (w * w + 1j * w * CU_GAMMA_BULK_EV) - wp2 / (w * w + 1j * w * g_r)
    return eps


def depolarisation(aspect):
    """(L_long, L_short, L_short) of a prolate spheroid with long/short axis ratio `aspect`."""
    if abs(aspect - 1.0) < 1e-12:
        return (1 / 3, 1 / 3, 1 / 3)
    if aspect < 1.0:
        sys.exit("--aspect: prolate spheroids only (aspect >= 1)")
    e2 = 1.0 - 1.0 / aspect**2
    e = math.sqrt(e2)
    l_long = (1.0 - e2) / e2 * (-1.0 + math.log((1.0 + e) / (1.0 - e)) / (2.0 * e))
    l_short = (1.0 - l_long) / 2.0
    return (l_long, l_short, l_short)


def alpha_per_volume_fraction(rows, lam, host_index=HOST_INDEX, aspect=1.0, radius_nm=None, axes=(0, 1, 2)):
    """Absorption coefficient per unit copper volume fraction, 1/nm: (2π n_m/λ) Im <α_j>/V,
    averaged over the principal axes `axes` (all three: random orientation)."""
    eps = copper_eps(rows, lam, radius_nm)
    eps_m = host_index**2
    ls = depolarisation(aspect)
    pol = sum((eps - eps_m) / (eps_m + ls[j] * (eps - eps_m)) for j in axes) / len(axes)
    return 2.0 * math.pi * host_index / lam * pol.imag


def band_figures(f, lo=360.0, hi=830.0, step=0.1, band=(500.0, 830.0)):
    """Peak of the visible band (largest local maximum in `band`), its half-maximum crossings,
    the global maximum, the lowest value on the band's blue side, and the crossings of the level
    halfway between that minimum and the peak (the width at half prominence)."""
    xs = [lo + step * i for i in range(int(round((hi - lo) / step)) + 1)]
    vs = [f(x) for x in xs]
    gmax = max(range(len(vs)), key=vs.__getitem__)
    peaks = [i for i in range(1, len(vs) - 1) if vs[i - 1] < vs[i] >= vs[i + 1] and band[0] <= xs[i] <= band[1]]
    if not peaks:
        return None
    p = max(peaks, key=vs.__getitem__)
    half = vs[p] / 2.0
    blue = next((xs[i] for i in range(p, -1, -1) if vs[i] < half), None)
    red = next((xs[i] for i in range(p, len(vs)) if vs[i] < half), None)
    valley = min(range(p + 1), key=vs.__getitem__)
    mid = (vs[p] + vs[valley]) / 2.0
    prom_blue = next((xs[i] for i in range(p, valley - 1, -1) if vs[i] < mid), None)
    prom_red = next((xs[i] for i in range(p, len(vs)) if vs[i] < mid), None)
    return {
        "prom_blue_nm": prom_blue,
        "prom_red_nm": prom_red,
        "peak_nm": xs[p],
        "peak": vs[p],
        "blue_half_nm": blue,
        "red_half_nm": red,
        "global_nm": xs[gmax],
        "global": vs[gmax],
        "valley_nm": xs[valley],
        "valley": vs[valley],
    }


def fmt5(v):
    """5 significant digits, trailing zeros kept."""
    if v == 0.0:
        return "0.0000"
    decimals = max(0, 4 - math.floor(math.log10(abs(v))))
    return f"{v:.{decimals}f}"


def header(args, fig, top):
    shape = "spheres" if args.aspect == 1.0 else f"randomly oriented prolate spheroids, aspect ratio {args.aspect:g}"
    size = (
        "no size correction (bulk Johnson & Christy epsilon)"
        if not args.radius_nm
        else f"Kreibig size damping for radius {args.radius_nm:g} nm "
        f"(gamma = gamma_bulk + A v_F / r, A = {KREIBIG_A:g}, v_F = 1.57e6 m/s, hbar omega_p = 8.8 eV, hbar gamma_bulk = 0.0955 eV)"
    )
    band = (
        f"the plasmon band peaks at {fig['peak_nm']:.1f} nm with {fig['peak'] / top:.4f}; "
        f"the largest value is at {fig['global_nm']:.1f} nm"
        if fig
        else "no local maximum in 500-830 nm"
    )
    return [
        "# Red Oregon sunstone body: absorption coefficient spectrum of colloidal metallic copper in labradorite.",
        "# DERIVED, NOT A MEASUREMENT: computed by scripts/sunstone-spectrum.py; no measured transmission spectrum is",
        "# available offline. A powder/diffuse-reflectance spectrum would not be a body colour either.",
        "# Formula: quasi-static (dipole) absorption, alpha(lambda) = f * 3 (2 pi n_m / lambda) * Im[(eps - eps_m) / (eps + 2 eps_m)]",
        "# (Bohren & Huffman 1983, Absorption and Scattering of Light by Small Particles, eq. 5.32; Kreibig & Vollmer 1995),",
        f"# particles: {shape}; {size}.",
        "# eps = (n + i k)^2 of copper: P. B. Johnson and R. W. Christy, Phys. Rev. B 6, 4370 (1972), data/metals/copper.csv,",
        "# n and k interpolated linearly in wavelength (the table has points at 520.9, 548.6, 582.1, 616.8 nm only).",
        f"# Host: labradorite, n_m = {args.host_index:g} (eps_m = n_m^2), non-absorbing, isotropic.",
        "# To be checked against the measured band of: S. Jin, A. C. Palke, N. D. Renfro, Z. Sun, Gems & Gemology 59(3), Fall 2023",
        "# (Special Colors and Optical Effects of Oregon Sunstone); A. M. Hofmeister and G. R. Rossman, Geology 13, 644-647 (1985).",
        "# Only the GIA abstract was readable offline, so the measured band position is NOT verified here; the shape (spheres,",
        "# random) follows a TEM study's abstract (red zones: Cu spheres/ellipsoids 8.7-12 nm across, aspect ratio 1-1.3;",
        "# 'Cu nanoparticle geometry as the key to bicolor behavior in Oregon sunstones', par.nsf.gov/biblio/10578762).",
        "# Not modelled: scattering by larger particles (needed for the red/green colours, Jin et al. 2023), aligned",
        "# elongated particles and pleochroism, the host's own Fe absorption.",
        f"# Normalisation: divided by the maximum over 360-830 nm (= 1.0); {band}.",
        "# The recipe scales it to the body's absorption per object unit.",
        "wavelength_nm,value",
    ]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--host-index", type=float, default=HOST_INDEX)
    ap.add_argument("--aspect", type=float, default=1.0, help="prolate spheroid aspect ratio (1 = spheres)")
    ap.add_argument("--radius-nm", type=float, default=None, help="Kreibig size damping for this radius")
    ap.add_argument("--out", default=OUT)
    ap.add_argument("--table", action="store_true", help="print band peaks against spheroid aspect ratio")
    args = ap.parse_args()

    rows = read_copper()

    def f(lam):
        return alpha_per_volume_fraction(rows, lam, args.host_index, args.aspect, args.radius_nm)

    def pinned(lam):
        return " (at a copper table point: an interpolation kink)" if any(abs(lam - r[0]) < 0.15 for r in rows) else ""

    values = [f(lam) for lam in GRID]
    top = max(values)
    norm = [v / top for v in values]
    if not all(math.isfinite(v) and v >= 0.0 for v in norm):
        sys.exit("non-finite or negative value")
    fig = band_figures(f)

    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "w", encoding="utf-8", newline="\n") as out:
        for line in header(args, fig, top):
            out.write(line + "\n")
        for lam, v in zip(GRID, norm):
            out.write(f"{lam},{fmt5(v)}\n")
    print(f"wrote {os.path.relpath(args.out, ROOT) if args.out.startswith(ROOT) else args.out} ({len(GRID)} rows, 360-830 nm)")

    at = dict(zip(GRID, norm))
    if fig:
        fwhm = None if fig["blue_half_nm"] is None or fig["red_half_nm"] is None else fig["red_half_nm"] - fig["blue_half_nm"]
        band_peak = fig["peak"] / top
        print(f"band peak: {fig['peak_nm']:.1f} nm{pinned(fig['peak_nm'])} (value {band_peak:.4f} of the file's maximum)")
        if fwhm is None:
            print(
                f"FWHM: undefined - the blue side never falls to half the band peak (interband absorption); "
                f"red half-maximum at {fig['red_half_nm']:.1f} nm, red-side HWHM {fig['red_half_nm'] - fig['peak_nm']:.1f} nm"
            )
        else:
            print(f"FWHM: {fwhm:.1f} nm ({fig['blue_half_nm']:.1f}-{fig['red_half_nm']:.1f} nm)")
        print(
            f"band contrast: peak / blue-side minimum ({fig['valley_nm']:.1f} nm) = {fig['peak'] / fig['valley']:.3f}; "
            f"largest value at {fig['global_nm']:.1f} nm"
        )
        if fig["prom_blue_nm"] is not None and fig["prom_red_nm"] is not None:
            print(
                f"width at half prominence (halfway between the {fig['valley_nm']:.1f} nm minimum and the peak): "
                f"{fig['prom_red_nm'] - fig['prom_blue_nm']:.1f} nm ({fig['prom_blue_nm']:.1f}-{fig['prom_red_nm']:.1f} nm)"
            )
        per_ppm = fig["peak"] * 1e6 * 1e-6 * LABRADORITE_DENSITY / CU_DENSITY  # 1/nm -> 1/mm, ppm by weight
        print(f"absolute scale: alpha at the band peak = {per_ppm:.4f} /mm per ppm (by weight) of copper present as such colloids")
        print(f"value(450)/value(peak) = {at[450] / band_peak:.4f}")
        print(f"value(650)/value(peak) = {at[650] / band_peak:.4f}")
    else:
        print("no band maximum in 500-830 nm")
        print(f"value(450)/max = {at[450]:.4f}, value(650)/max = {at[650]:.4f}")

    if args.table:
        print("\nband peak against prolate aspect ratio (host n = %g, radius %s):" % (args.host_index, args.radius_nm or "bulk"))
        print("aspect  long axis (E || axis)  short axes (E _|_ axis)  random-orientation mean")
        for aspect in (1.0, 1.1, 1.2, 1.3, 1.5, 2.0, 2.5, 3.0):
            cells = []
            for axes in ((0,), (1,), (0, 1, 2)):
                fg = band_figures(lambda lam: alpha_per_volume_fraction(rows, lam, args.host_index, aspect, args.radius_nm, axes))
                cells.append(f"{fg['peak_nm']:6.1f} nm{'*' if pinned(fg['peak_nm']) else ' '}" if fg else "  none   ")
            print(f"{aspect:5.1f}   {cells[0]:>20}   {cells[1]:>22}   {cells[2]:>22}")
        print("* at a point of the copper table: a kink of the linear interpolation, so +-half the table spacing")


if __name__ == "__main__":
    main()
