#!/usr/bin/env python3
"""Polarised transport of lapidary against Mitsuba 3's polarised spectral variant (issue 40).
Mitsuba is never a dependency of the crate or its tests: run this by hand with a Python that has
`mitsuba` and `numpy` (Mitsuba's `scalar_spectral_polarized` variant needs no LLVM):

    python3 -m venv /tmp/mi-venv && /tmp/mi-venv/bin/pip install mitsuba numpy
    cargo build --release
    /tmp/mi-venv/bin/python scripts/mitsuba-polarised.py [--spp N] [--size S] [OUT_DIR]

The scene: a clear glass sphere (IOR 1.5, radius 1) at the origin, a pinhole camera at (0, 0, 4)
looking at it (vertical field of view 30°, box filter), a black sky and a 6 × 6 rectangle light
of radiance 1 at z = −3 facing the camera, so that the sphere shows the light refracted through
it — partially polarised by the two Fresnel transmissions (radially, p-like) and by internal
reflections. Mitsuba's `stokes` integrator writes S0–S3 in the sensor's frame; lapidary measures
them with its camera analyser at 0°, 90°, 45° and 135° from the image's right
(`I(θ) = ½ (S0 + S1 cos 2θ + S2 sin 2θ)`, so `S0 = I(0) + I(90)`, `S1 = I(0) − I(90)`,
`S2 = I(45) − I(135)`), spectral and polarised.

`--scene conductor`: the sphere is instead a rough conductor (Beckmann α 0.2, Smith's separable
masking, index 1.5 + 0.5i at every wavelength — a weak absorber whose s and p reflectances part
widely; lapidary's RGB transport with that index in every channel, Mitsuba's spectral one with
it constant) in a white constant sky: every micro-facet polarises by its own Fresnel matrix, in
BSDF sampling and in light sampling of the sky.

`--scene rough-glass`: the glass sphere's boundary is instead rough (Beckmann α 0.2, Smith's
separable masking, no energy compensation — Mitsuba's `roughdielectric`): every micro-facet
reflects and refracts by its own Fresnel matrices, in BSDF sampling and in light sampling
(from inside, through the boundary).

Printed: over the pixels on the sphere, per quadrant of the image (where S2 lives: the pattern
turns with the azimuth) and per wedge about the horizontal and the vertical (where S1 lives), the means of S0 and of S1/S0 and S2/S0 weighted by S0 from both renderers, with
lapidary's standard error from its variance channels. Outputs (EXRs) go to OUT_DIR (default
target/mitsuba-polarised).
"""

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent

RECIPE = """(
    materials: {{}},
    body: (ior: 1.5),
    surface: Body,
    stage: (
        shape: Sphere(radius: 1.0),
        ground: Off,
        environment: Constant(Gray(0.0)),
        lights: [Rect(center: (0.0, 0.0, -3.0), target: (0.0, 0.0, 0.0), size: (6.0, 6.0),
                      radiance: Gray(1.0))],
        camera: Perspective(from: (0.0, 0.0, 4.0), to: (0.0, 0.0, 0.0), fov: 30.0),
        analyser: {analyser},
        render: (width: {size}, height: {size}, spp: {spp}, max_depth: 16, filter: Box,
                 sampler: Independent),
    ),
)
"""


ROUGH_GLASS = RECIPE.replace(
    "body: (ior: 1.5),",
    "body: (ior: 1.5, alpha: 0.2, distribution: Beckmann, masking: SmithSeparable,\n"
    "           compensation: false),")


CONDUCTOR = """(
    materials: {{ "metal": (base: Conductor(metal: Complex(n: (1.5, 1.5, 1.5), k: (0.5, 0.5, 0.5)),
                                           alpha: 0.2),
                           distribution: Beckmann, masking: SmithSeparable, compensation: false) }},
    surface: Material("metal"),
    stage: (
        shape: Sphere(radius: 1.0),
        ground: Off,
        environment: Constant(Gray(1.0)),
        lights: [],
        camera: Perspective(from: (0.0, 0.0, 4.0), to: (0.0, 0.0, 0.0), fov: 30.0),
        analyser: {analyser},
        render: (width: {size}, height: {size}, spp: {spp}, max_depth: 16, filter: Box,
                 sampler: Independent),
    ),
)
"""


def mitsuba(size, spp, out, scene_kind="sphere"):
    import mitsuba as mi
    mi.set_variant("scalar_spectral_polarized")
    T = mi.ScalarTransform4f
    sphere_scene = {
        "sphere": {"type": "sphere", "radius": 1.0,
                   "bsdf": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}},
        # Mitsuba's rectangle is [-1, 1]² in z = 0, emitting toward +z; look_at turns +z to the
        # target.
        "light": {"type": "rectangle",
                  "to_world": T().look_at(origin=[0, 0, -3], target=[0, 0, 0], up=[0, 1, 0])
                  @ T().scale([3.0, 3.0, 1.0]),
                  "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [1, 1, 1]}}},
    }
    if scene_kind == "rough-glass":
        sphere_scene["sphere"]["bsdf"] = {"type": "roughdielectric", "distribution": "beckmann",
                                          "alpha": 0.2, "int_ior": 1.5, "ext_ior": 1.0}
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "stokes", "integrator": {"type": "path", "max_depth": 16}},
        "sensor": {
            "type": "perspective", "fov": 30.0, "fov_axis": "y",
            "to_world": T().look_at(origin=[0, 0, 4], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size, "height": size,
                     "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        **(CONDUCTOR_SCENE if scene_kind == "conductor" else sphere_scene),
    })
    # The stokes integrator's channels: the colour (3), then S0, S1, S2, S3 × (R, G, B)
    # (`aov_names()`).
    return np.array(mi.render(scene))


CONDUCTOR_SCENE = {
    "sphere": {"type": "sphere", "radius": 1.0,
               "bsdf": {"type": "roughconductor", "distribution": "beckmann", "alpha": 0.2,
                        "eta": 1.5, "k": 0.5}},
    "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [1, 1, 1]}},
}


def lapidary(size, spp, out, scene_kind="sphere"):
    bin_ = ROOT / "target" / "release" / "lapidary"
    import mitsuba as mi
    imgs = {}
    for a in (0, 90, 45, 135):
        recipe = out / f"sphere-{a}.ron"
        text = {"conductor": CONDUCTOR, "rough-glass": ROUGH_GLASS}.get(scene_kind, RECIPE)
        recipe.write_text(text.format(analyser=float(a), size=size, spp=spp))
        exr = out / f"lapidary-{a}.exr"
        # The conductor's index is an RGB one: its polarisation runs on RGB paths.
        transport = ["--spectral", "off"] if scene_kind == "conductor" else ["--spectral"]
        subprocess.run([str(bin_), "render", str(recipe), "-o", str(exr), "--no-png",
                        *transport, "--quiet"], check=True)
        bmp = mi.Bitmap(str(exr))
        names = [f.name for f in bmp.struct_()]
        arr = np.array(bmp)
        ch = {name: arr[..., i] for i, name in enumerate(names)}
        mean = (ch["R"] + ch["G"] + ch["B"]) / 3
        var = (ch["variance.R"] + ch["variance.G"] + ch["variance.B"]) / 9
        imgs[a] = (mean, var)
    return imgs


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out", nargs="?", default=str(ROOT / "target" / "mitsuba-polarised"))
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--size", type=int, default=96)
    ap.add_argument("--scene", choices=("sphere", "conductor", "rough-glass"),
                    default="sphere")
    a = ap.parse_args()
    out = Path(a.out) / a.scene
    out.mkdir(parents=True, exist_ok=True)
    arr = mitsuba(a.size, a.spp, out, a.scene)
    nch = arr.shape[2]
    # Channels: the path integrator's RGB(A?) then S0..S3 × RGB; the last 12 are the Stokes.
    stokes = arr[..., nch - 12:].reshape(a.size, a.size, 4, 3).mean(axis=3)
    m = {k: stokes[..., i] for i, k in enumerate(("S0", "S1", "S2", "S3"))}
    imgs = lapidary(a.size, a.spp, out, a.scene)
    l = {"S0": imgs[0][0] + imgs[90][0], "S1": imgs[0][0] - imgs[90][0],
         "S2": imgs[45][0] - imgs[135][0]}
    var = {"S0": imgs[0][1] + imgs[90][1], "S1": imgs[0][1] + imgs[90][1],
           "S2": imgs[45][1] + imgs[135][1]}
    # Pixels whose centre ray hits the sphere.
    n = a.size
    ys, xs = np.mgrid[0:n, 0:n]
    px = (xs + 0.5) / n * 2 - 1
    py = 1 - (ys + 0.5) / n * 2
    t = np.tan(np.radians(15))
    d = np.stack([px * t, py * t, -np.ones_like(px)], -1)
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = np.array([0, 0, 4.0])
    b = (d @ o)
    disc = b * b - (o @ o - 1.0)
    on = disc > 0.02
    print(f"{n}×{n}, {a.spp} spp each; pixels on the sphere: {on.sum()}")
    print(f"{'region':>11} {'S0 mi':>9} {'S0 lap':>9} {'S1/S0 mi':>10} {'S1/S0 lap':>16} "
          f"{'S2/S0 mi':>10} {'S2/S0 lap':>16}")
    for name, q in (("upper right", (px > 0) & (py > 0)), ("upper left", (px < 0) & (py > 0)),
                    ("lower left", (px < 0) & (py < 0)), ("lower right", (px > 0) & (py < 0)),
                    ("left/right", np.abs(px) > np.abs(py)),
                    ("top/bottom", np.abs(py) > np.abs(px)), ("all", np.ones_like(on))):
        sel = on & q
        k = sel.sum()
        row = [m["S0"][sel].mean(), l["S0"][sel].mean()]
        se0 = np.sqrt(var["S0"][sel].sum()) / k
        cells = []
        for s in ("S1", "S2"):
            mi_r = m[s][sel].sum() / m["S0"][sel].sum()
            la_r = l[s][sel].sum() / l["S0"][sel].sum()
            se = np.sqrt(var[s][sel].sum()) / l["S0"][sel].sum()
            cells += [f"{mi_r:10.4f}", f"{la_r:8.4f} ± {se:.4f}"]
        print(f"{name:>11} {row[0]:9.4f} {row[1]:9.4f} ± {se0:.4f} " + " ".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main())
