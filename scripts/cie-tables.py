#!/usr/bin/env python3
"""Writes the colorimetric tables of src/spectrum/cie.rs into src/spectrum/data/.

* cie1931_2deg.csv — the CIE 1931 2° standard observer's colour-matching functions x̄, ȳ, z̄ at
  1 nm, 360–830 nm, as tabulated in CIE 015:2004 and CIE 018:2019, here as shipped
  by colour-science (`colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]`).
* d65.csv — CIE standard illuminant D65, relative spectral power distribution at 5 nm,
  360–830 nm (CIE S 014-2:2006 / ISO 11664-2:2007). colour-science ships the CIE table to 780 nm
  (`colour.SDS_ILLUMINANTS["D65"]`); 785–830 nm are computed by the CIE daylight formula
  S(λ) = S0(λ) + M1 S1(λ) + M2 S2(λ) (CIE 015:2004, basis functions S0, S1, S2 as shipped by
  colour-science) with M1, M2 rounded to three decimals as the CIE does (M1 = −0.295,
  M2 = −0.689 for D65), rounded to four decimals (ties down). The same formula reproduces the shipped
  300–780 nm values to 1e-3.

Needs colour-science (`pip install colour-science`). Run from the repository root:
`python3 scripts/cie-tables.py`.
"""

from decimal import ROUND_HALF_DOWN, Decimal

import numpy as np
import colour
from colour.colorimetry.datasets.illuminants import (
    SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES as BASIS,
)

OUT = "src/spectrum/data/"


def main():
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    w = np.asarray(cmfs.wavelengths)
    v = np.asarray(cmfs.values)
    assert w[0] == 360 and w[-1] == 830 and len(w) == 471
    with open(OUT + "cie1931_2deg.csv", "w") as f:
        f.write(
            "# CIE 1931 2° standard colorimetric observer: colour-matching functions at 1 nm.\n"
            "# Source: CIE 015:2004 Colorimetry, 3rd ed. (also CIE 018:2019), as shipped\n"
            f"# by colour-science {colour.__version__} (MSDS_CMFS['CIE 1931 2 Degree Standard Observer']).\n"
            "# Written by scripts/cie-tables.py.\n"
            "lambda_nm,x_bar,y_bar,z_bar\n"
        )
        for lam, (x, y, z) in zip(w, v):
            f.write(f"{int(lam)},{float(x)!r},{float(y)!r},{float(z)!r}\n")

    d65 = colour.SDS_ILLUMINANTS["D65"]
    s0, s1, s2 = (BASIS[k] for k in ("S0", "S1", "S2"))
    with open(OUT + "d65.csv", "w") as f:
        f.write(
            "# CIE standard illuminant D65: relative spectral power distribution at 5 nm (S(560) = 100).\n"
            "# Source: CIE S 014-2:2006 / ISO 11664-2:2007, 360-780 nm as shipped by colour-science\n"
            f"# {colour.__version__} (SDS_ILLUMINANTS['D65']); 785-830 nm from the CIE daylight formula\n"
            "# S0 + M1 S1 + M2 S2 with M1 = -0.295, M2 = -0.689 (CIE 015:2004),\n"
            "# rounded to four decimals (ties down). Written by scripts/cie-tables.py.\n"
            "lambda_nm,d65\n"
        )
        for lam in range(360, 835, 5):
            if lam <= 780:
                val = float(d65[lam])
            else:
                # the basis to its two tabulated decimals, exact decimal arithmetic, ties down
                # (795, 805, 825 nm are ties, which the CIE table rounds down: 55.70545 → 55.7054)
                d = [Decimal(repr(round(float(b[lam]), 2))) for b in (s0, s1, s2)]
                exact = d[0] + Decimal("-0.295") * d[1] + Decimal("-0.689") * d[2]
                val = float(exact.quantize(Decimal("0.0001"), rounding=ROUND_HALF_DOWN))
            f.write(f"{lam},{val!r}\n")


if __name__ == "__main__":
    main()
