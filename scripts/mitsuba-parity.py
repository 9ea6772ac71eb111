#!/usr/bin/env python3
"""Microfacet parity of lapidary with Mitsuba 3 (issue 16). Mitsuba is never a dependency of the
crate or its tests: this script is run by hand, with a Python that has `mitsuba` and `numpy`:

    python3 -m venv /tmp/mi-venv && /tmp/mi-venv/bin/pip install mitsuba numpy
    cargo build --release
    /tmp/mi-venv/bin/python scripts/mitsuba-parity.py [OUT_DIR]      # default target/parity

The scene: a unit sphere at the origin, a pinhole camera at (0, 0, 4) looking at the origin with a
30° vertical field of view (lapidary's `fov` is vertical; Mitsuba gets `fov_axis = "y"`),
256×256 pixels, a 1-pixel box filter, no floor, under
  sky:  a constant sky of radiance 1, or
  rect: a constant sky of radiance 0.2 and a one-sided 1×1 rectangle light of radiance 10 at
        (2, 3, 3) facing the origin.
The lapidary recipes are scripts/parity/{sky,rect}-MATERIAL.ron (materials in
scripts/parity/materials.ron); the Mitsuba scenes are built below from the same numbers.

Mitsuba (scalar_rgb) renders each reference in `--mi-passes` independent passes (seeds 0, 1, …)
whose spread gives the variance of the mean, written as `variance.R/G/B` next to `R G B` so that
`lapidary compare` can run its z-tests; an `R G B`-only copy gets the no-variance verdict
(relMSE and mean ratios). Lapidary renders with the independent sampler, so its `variance.*`
channels are honest standard errors.

Outputs in OUT_DIR: mitsuba/LIGHT-BSDF.exr (+ -rgb.exr), lapidary/LIGHT-MATERIAL.exr,
results.json and results.md (the tables of docs/parity.md). Mitsuba references are reused when a
previous run made them with the same settings (`--force` renders them again).

Reported per material and lighting, per channel: the ratio of means lapidary / Mitsuba over the
pixels wholly on the sphere (all four corners' rays hit it), overall and per θo band (θo = angle
between the view direction and the sphere normal at the pixel centre: 0–30, 30–60, 60–80,
80–90°), ± the standard error of lapidary's mean (from its variance channel; Mitsuba's own is
given in results.json), and the `lapidary compare` verdicts.
"""

import argparse
import json
import math
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
PARITY = ROOT / "scripts" / "parity"

# Mitsuba's RGB (n, k) of Au in its rgb variants, as written in scripts/parity/materials.ron
# ("…-mink" materials); checked against the installed Mitsuba at start.
MI_AU_ETA = (0.143036, 0.375307, 1.44205)
MI_AU_K = (3.983, 2.38556, 1.60336)

LIGHTINGS = ("sky", "rect")
BANDS = ((0.0, 30.0), (30.0, 60.0), (60.0, 80.0), (80.0, 90.0))

# Mitsuba BSDFs, by reference name.
MI_BSDFS = {
    "diffuse": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}},
    "au-beckmann": {"type": "roughconductor", "material": "Au",
                    "distribution": "beckmann", "alpha": 0.2},
    "au-ggx": {"type": "roughconductor", "material": "Au", "distribution": "ggx", "alpha": 0.2},
    "rough-plastic": {"type": "roughplastic", "distribution": "beckmann", "alpha": 0.1,
                      "int_ior": 1.5, "ext_ior": 1.0, "nonlinear": True,
                      "diffuse_reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}},
    "smooth-plastic": {"type": "plastic", "int_ior": 1.5, "ext_ior": 1.0, "nonlinear": True,
                       "diffuse_reflectance": {"type": "rgb", "value": [0.5, 0.5, 0.5]}},
    # Translucent bodies: a sphere of glass (Mitsuba's `roughdielectric` has no multiple-scattering
    # compensation and uses the separable Smith masking, hence lapidary's `compensation: false`,
    # `masking: SmithSeparable`), with an absorbing interior where "interior" is given (σa per
    # unit; rendered with `volpath`).
    "glass-rough": {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3,
                    "int_ior": 1.5, "ext_ior": 1.0},
    "glass-absorbing": {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0,
                        "interior": [0.2, 0.5, 1.0]},
    "glass-rough-absorbing": {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.3,
                              "int_ior": 1.5, "ext_ior": 1.0, "interior": [0.2, 0.5, 1.0]},
}

# Lapidary materials (scripts/parity/materials.ron) and the Mitsuba BSDF each is compared with.
CASES = (
    ("diffuse", "diffuse"),
    *[(f"au-{d}{v}", f"au-{d}") for d in ("beckmann", "ggx")
      for v in ("", "-nocomp", "-nocomp-mink", "-smith-nocomp-mink", "-vcavity-nocomp-mink")],
    ("rough-plastic", "rough-plastic"),
    ("rough-plastic-vcavity", "rough-plastic"),
    ("rough-plastic-reference", "rough-plastic"),
    ("rough-plastic-nocomp", "rough-plastic"),
    ("rough-plastic-reference-nocomp", "rough-plastic"),
    ("smooth-plastic", "smooth-plastic"),
    ("smooth-plastic-reference", "smooth-plastic"),
    ("glass-rough-nocomp", "glass-rough"),
    ("glass-rough", "glass-rough"),
    ("glass-absorbing", "glass-absorbing"),
    ("glass-rough-absorbing-nocomp", "glass-rough-absorbing"),
)


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("out", nargs="?", default=str(ROOT / "target" / "parity"),
                   help="output directory (default target/parity)")
    p.add_argument("--lapidary", default=str(ROOT / "target" / "release" / "lapidary"),
                   help="the lapidary binary (default target/release/lapidary; build it first)")
    p.add_argument("--size", type=int, default=256, help="image side in pixels (default 256)")
    p.add_argument("--lap-spp", type=int, default=256, help="lapidary spp (default 256)")
    p.add_argument("--mi-spp", type=int, default=1024, help="Mitsuba spp (default 1024)")
    p.add_argument("--mi-passes", type=int, default=16,
                   help="independent Mitsuba passes the spp is split into (default 16)")
    p.add_argument("--seed", type=int, default=7, help="lapidary's seed (default 7)")
    p.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (default scalar_rgb)")
    p.add_argument("--only", nargs="*", default=None,
                   help="only these cases (material names, or LIGHT-MATERIAL)")
    p.add_argument("--force", action="store_true", help="render the Mitsuba references again")
    p.add_argument("--report-only", action="store_true",
                   help="only rewrite OUT/results.md from OUT/results.json (no rendering)")
    a = p.parse_args()
    if a.mi_spp % a.mi_passes:
        p.error("--mi-spp must be a multiple of --mi-passes")
    return a


# ---------------------------------------------------------------------------------------------
# Mitsuba


def mi_scene(mi, lighting, bsdf, size):
    T = mi.ScalarTransform4f
    desc = dict(MI_BSDFS[bsdf])
    interior = desc.pop("interior", None)
    glass = "dielectric" in desc["type"]
    scene = {
        "type": "scene",
        # Lapidary's default depth is 8 scattering events; Mitsuba counts the camera segment too.
        # On a convex sphere every path scatters once, so depth only has to be ≥ 2. Light
        # crosses a glass sphere many times: 64 events in lapidary (the recipes' max_depth).
        "integrator": {"type": "volpath" if interior else "path",
                       "max_depth": 65 if glass else 9},
        "sensor": {
            "type": "perspective", "fov": 30.0, "fov_axis": "y",
            "to_world": T().look_at(origin=[0, 0, 4], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "pixel_format": "rgb",
                     "rfilter": {"type": "box"}},  # Mitsuba's box: radius 0.5 px, one pixel
            "sampler": {"type": "independent"},
        },
        "sphere": {"type": "sphere", "center": [0, 0, 0], "radius": 1.0, "bsdf": desc},
    }
    if interior:
        scene["sphere"]["interior"] = {
            "type": "homogeneous", "albedo": 0.0,
            "sigma_t": {"type": "rgb", "value": interior}}
    if lighting == "sky":
        scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0] * 3}}
    else:
        scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": [0.2] * 3}}
        # Mitsuba's rectangle is [-1, 1]² in z = 0, emitting towards +z; look_at turns +z
        # towards the target. One-sided, like lapidary's Rect (two_sided: false).
        scene["light"] = {
            "type": "rectangle",
            "to_world": T().look_at(origin=[2, 3, 3], target=[0, 0, 0], up=[0, 1, 0])
            @ T().scale([0.5, 0.5, 1.0]),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [10.0] * 3}},
        }
    return scene


def mi_settings(args, mi, lighting, bsdf):
    return {"mitsuba": mi.__version__, "variant": args.variant, "size": args.size,
            "spp": args.mi_spp, "passes": args.mi_passes, "lighting": lighting,
            "bsdf": MI_BSDFS[bsdf]}


def render_mitsuba(args, mi, lighting, bsdf, out):
    exr = out / "mitsuba" / f"{lighting}-{bsdf}.exr"
    rgb_exr = exr.with_name(f"{lighting}-{bsdf}-rgb.exr")
    meta = exr.with_suffix(".json")
    settings = mi_settings(args, mi, lighting, bsdf)
    if not args.force and exr.exists() and rgb_exr.exists() and meta.exists():
        if json.loads(meta.read_text()).get("settings") == settings:
            print(f"  mitsuba {lighting}-{bsdf}: reusing {exr.relative_to(out)}", flush=True)
            return exr, rgb_exr
    scene = mi.load_dict(mi_scene(mi, lighting, bsdf, args.size))
    per = args.mi_spp // args.mi_passes
    t0 = time.time()
    passes = []
    for k in range(args.mi_passes):
        passes.append(np.array(mi.render(scene, spp=per, seed=k), dtype=np.float64))
    secs = time.time() - t0
    stack = np.stack(passes)                         # passes × H × W × 3
    mean = stack.mean(axis=0)
    var_of_mean = stack.var(axis=0, ddof=1) / args.mi_passes
    samples = np.full(mean.shape[:2] + (1,), float(args.mi_spp))
    names = ["R", "G", "B", "variance.R", "variance.G", "variance.B", "samples.Y"]
    data = np.concatenate([mean, var_of_mean, samples], axis=2).astype(np.float32)
    exr.parent.mkdir(parents=True, exist_ok=True)
    mi.Bitmap(data, mi.Bitmap.PixelFormat.MultiChannel, names).write(str(exr))
    mi.Bitmap(mean.astype(np.float32), mi.Bitmap.PixelFormat.MultiChannel,
              ["R", "G", "B"]).write(str(rgb_exr))
    meta.write_text(json.dumps({"settings": settings, "seconds": secs}, indent=1))
    print(f"  mitsuba {lighting}-{bsdf}: {args.mi_spp} spp in {args.mi_passes} passes, "
          f"{secs:.1f} s", flush=True)
    return exr, rgb_exr


def check_mitsuba_au(mi):
    """Mitsuba's RGB (n, k) of Au, checked against the constants the recipes use."""
    b = mi.load_dict({"type": "roughconductor", "material": "Au", "alpha": 0.2})
    p = mi.traverse(b)
    eta = [float(v) for v in np.array(p["eta.value"]).ravel()]
    k = [float(v) for v in np.array(p["k.value"]).ravel()]
    same = np.allclose(eta, MI_AU_ETA, rtol=1e-5) and np.allclose(k, MI_AU_K, rtol=1e-5)
    if not same:
        print(f"warning: this Mitsuba's Au is eta {eta}, k {k}; scripts/parity/materials.ron "
              f"has eta {MI_AU_ETA}, k {MI_AU_K}: the -mink rows no longer use Mitsuba's values",
              file=sys.stderr)
    return eta, k


# ---------------------------------------------------------------------------------------------
# lapidary


def lapidary_gold():
    """Metal::Gold's (n, k) as written in src/bsdf/fresnel.rs (for the report only)."""
    src = (ROOT / "src" / "bsdf" / "fresnel.rs").read_text()
    m = re.search(r"Metal::Gold\s*=>\s*\(\s*Rgb::new\(([^)]*)\),\s*Rgb::new\(([^)]*)\)", src)
    if not m:
        return None
    return [[float(v) for v in g.split(",") if v.strip()] for g in m.groups()]


def render_lapidary(args, lighting, material, out):
    recipe = PARITY / f"{lighting}-{material}.ron"
    exr = out / "lapidary" / f"{lighting}-{material}.exr"
    exr.parent.mkdir(parents=True, exist_ok=True)
    cmd = [args.lapidary, "render", str(recipe), "-o", str(exr), "--no-png",
           "--spp", str(args.lap_spp), "--size", f"{args.size}x{args.size}",
           "--seed", str(args.seed), "--sampler", "independent", "--quiet"]
    t0 = time.time()
    subprocess.run(cmd, check=True)
    print(f"  lapidary {lighting}-{material}: {args.lap_spp} spp, {time.time() - t0:.1f} s",
          flush=True)
    return exr, cmd


def compare(args, test, ref):
    r = subprocess.run([args.lapidary, "compare", str(test), str(ref)],
                       capture_output=True, text=True)
    lines = r.stdout.splitlines()
    verdict = next((l.split(None, 1)[1] for l in lines if l.strip().startswith("verdict")), "?")
    return {"exit": r.returncode, "verdict": verdict.strip(), "report": r.stdout + r.stderr}


# ---------------------------------------------------------------------------------------------
# statistics


def read_channels(mi, path):
    bmp = mi.Bitmap(str(path))
    names = [f.name for f in bmp.struct_()]
    arr = np.array(bmp, dtype=np.float64)
    if arr.ndim == 2:
        arr = arr[..., None]
    return {n: arr[..., i] for i, n in enumerate(names)}


def sphere_geometry(size):
    """cos θo at each pixel centre and whether the pixel lies wholly on the sphere, for
    lapidary's camera (src/render/camera.rs): right = +x, up = +y, forward = −z, film y down."""
    half = math.tan(math.radians(15.0))
    o = np.array([0.0, 0.0, 4.0])

    def rays(fx, fy):
        sx = (2.0 * fx / size - 1.0) * half
        sy = (1.0 - 2.0 * fy / size) * half
        d = np.stack([sx, sy, -np.ones_like(sx)], axis=-1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)

    def hits(d):
        b = d @ o
        disc = b * b - (o @ o - 1.0)
        return disc, b

    j, i = np.mgrid[0:size, 0:size].astype(np.float64)
    d = rays(i + 0.5, j + 0.5)
    disc, b = hits(d)
    t = -b - np.sqrt(np.maximum(disc, 0.0))
    p = o + t[..., None] * d
    cos_o = np.clip(-(d * p).sum(-1), -1.0, 1.0)
    whole = np.ones((size, size), bool)
    for dx in (0.0, 1.0):
        for dy in (0.0, 1.0):
            whole &= hits(rays(i + dx, j + dy))[0] > 0.0
    return np.degrees(np.arccos(cos_o)), whole


def ratios(lap, ref, theta, mask):
    out = {}
    for name, (lo, hi) in [("all", (0.0, 90.0))] + [(f"{int(a)}-{int(b)}", (a, b))
                                                      for a, b in BANDS]:
        m = mask & (theta >= lo) & (theta < hi) if name != "all" else mask
        row = {"pixels": int(m.sum())}
        for c in "RGB":
            st, sr = lap[c][m].sum(), ref[c][m].sum()
            se_t = math.sqrt(lap["variance." + c][m].sum())
            se_r = math.sqrt(ref["variance." + c][m].sum()) if "variance." + c in ref else 0.0
            q = st / sr if sr > 0 else float("nan")
            row[c] = {"ratio": q, "se_lapidary": se_t / sr if sr > 0 else float("nan"),
                      "se_mitsuba": q * se_r / sr if sr > 0 else float("nan")}
        out[name] = row
    return out


# ---------------------------------------------------------------------------------------------
# report


def fmt_cell(row):
    r = " / ".join(f"{row[c]['ratio']:.4f}" for c in "RGB")
    se = max(row[c]["se_lapidary"] for c in "RGB")
    return f"{r} ±{se:.1g}"


def markdown(results, args, mi_version, eta, k, gold):
    bands = ["all"] + [f"{int(a)}-{int(b)}" for a, b in BANDS]
    lines = [f"Mitsuba {mi_version} `{args.variant}`, {args.mi_spp} spp ({args.mi_passes} passes); "
             f"lapidary {args.lap_spp} spp (independent sampler, seed {args.seed}); "
             f"{args.size}×{args.size}.", "",
             f"Mitsuba's RGB Au: eta = ({', '.join(f'{v:.6g}' for v in eta)}), "
             f"k = ({', '.join(f'{v:.6g}' for v in k)}); lapidary's `Metal::Gold`: "
             + (f"n = {tuple(gold[0])}, k = {tuple(gold[1])}." if gold else "(not found)."), ""]
    for lighting in LIGHTINGS:
        rows = [r for r in results if r["lighting"] == lighting]
        if not rows:
            continue
        title = {"sky": "constant sky 1", "rect": "constant sky 0.2 + 1×1 rectangle light 10"}
        lines += [f"**{lighting}** ({title[lighting]}): lapidary / Mitsuba, R / G / B "
                  f"(± largest standard error of lapidary's mean)", ""]
        head = "| lapidary material | Mitsuba | " + " | ".join(
            ("all θo" if b == "all" else f"θo {b}°") for b in bands) + " | compare (z) | compare (no var) |"
        lines += [head, "|" + "---|" * (len(bands) + 4)]
        for r in rows:
            cells = [fmt_cell(r["ratios"][b]) for b in bands]
            cz = r["compare_z"]["verdict"].split()[0]
            cn = r["compare_rgb"]["verdict"].split()[0]
            lines.append(f"| `{r['material']}` | `{r['mitsuba']}` | " + " | ".join(cells)
                         + f" | {cz} | {cn} |")
        px = rows[0]["ratios"]
        lines += ["", "pixels per band: " + ", ".join(f"{b} {px[b]['pixels']}" for b in bands), ""]
    return "\n".join(lines) + "\n"


def main():
    args = parse_args()
    if args.report_only:
        out = Path(args.out).resolve()
        summary = json.loads((out / "results.json").read_text())
        for key, v in summary["args"].items():
            if key not in ("out", "report_only", "only"):
                setattr(args, key, v)
        md = markdown(summary["results"], args, summary["mitsuba"], summary["au_eta"],
                      summary["au_k"], summary.get("lapidary_gold_nk"))
        (out / "results.md").write_text(md)
        print(md)
        return
    import mitsuba as mi
    mi.set_variant(args.variant)
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    if not Path(args.lapidary).exists():
        sys.exit(f"{args.lapidary}: no such binary (run `cargo build --release` first)")
    eta, k = check_mitsuba_au(mi)
    gold = lapidary_gold()
    print(f"Mitsuba {mi.__version__} ({args.variant}); RGB Au eta {eta}, k {k}")
    print(f"lapidary Metal::Gold (src/bsdf/fresnel.rs): n, k = {gold}")

    cases = [(l, m, ref) for l in LIGHTINGS for m, ref in CASES
             if args.only is None or m in args.only or f"{l}-{m}" in args.only]
    cases = [c for c in cases if (PARITY / f"{c[0]}-{c[1]}.ron").exists()]
    theta, mask = sphere_geometry(args.size)
    refs = {}
    results = []
    for lighting, material, ref in cases:
        if (lighting, ref) not in refs:
            refs[(lighting, ref)] = render_mitsuba(args, mi, lighting, ref, out)
        ref_exr, ref_rgb = refs[(lighting, ref)]
        lap_exr, cmd = render_lapidary(args, lighting, material, out)
        lap = read_channels(mi, lap_exr)
        mit = read_channels(mi, ref_exr)
        res = {"lighting": lighting, "material": material, "mitsuba": ref,
               "lapidary_exr": str(lap_exr), "mitsuba_exr": str(ref_exr),
               "lapidary_command": " ".join(cmd),
               "ratios": ratios(lap, mit, theta, mask),
               "compare_z": compare(args, lap_exr, ref_exr),
               "compare_rgb": compare(args, lap_exr, ref_rgb)}
        a = res["ratios"]["all"]
        print(f"    {lighting}-{material} / {ref}: " + "  ".join(
            f"{c} {a[c]['ratio']:.4f}±{a[c]['se_lapidary']:.4f}" for c in "RGB")
            + f"   compare: {res['compare_z']['verdict'].split()[0]} (z), "
              f"{res['compare_rgb']['verdict'].split()[0]} (no variance)", flush=True)
        results.append(res)

    summary = {"mitsuba": mi.__version__, "variant": args.variant, "au_eta": eta, "au_k": k,
               "lapidary_gold_nk": gold,
               "args": vars(args), "results": results}
    (out / "results.json").write_text(json.dumps(summary, indent=1))
    md = markdown(results, args, mi.__version__, eta, k, gold)
    (out / "results.md").write_text(md)
    print()
    print(md)


if __name__ == "__main__":
    main()
