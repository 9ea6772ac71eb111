#!/usr/bin/env python3
"""Writes a round brilliant cut gemstone as a closed triangle mesh (Wavefront OBJ).

Proportions: Marcel Tolkowsky's ideal angles from "Diamond Design" (1919), crown angle 34.5° and
pavilion angle 40.75°, with the 56% table of modern practice instead of his 53%; star length 50%
(of the way from table edge to girdle) and lower-girdle length 77% (of the way from girdle to
culet, as GIA measures it), usual values for today's well-cut stones; a pointed culet.

The 57 facets of a round brilliant without culet facet: crown with table (a regular octagon,
measured corner to corner), 8 star, 8 bezel (kites at the crown angle) and 16 upper-girdle
facets; pavilion with 8 main (kites at the pavilion angle, meeting in the culet) and 16
lower-girdle facets; between them an N-sided prism girdle (--girdle-sides, a multiple of 16).
As on a real stone, whose girdle is a cylinder, the upper/lower-girdle facets cut into the
girdle between the 16 facet junctions: the girdle vertices there lie on those facet planes, so
every facet is exactly planar; the girdle is GIRDLE thick halfway between junctions (its
thinnest, for N >= 32) and thickest at the junctions. Each facet is fanned into triangles.
Girdle radius 1, y up (table at +y, culet at -y), girdle centred on the y axis.

Usage (from anywhere; the default output is assets/brilliant.obj in the repository):
    python3 scripts/brilliant-mesh.py [--out PATH] [--girdle-sides N] [--force]
    python3 scripts/brilliant-mesh.py --check [--girdle-sides N]   # self-test, writes nothing
"""

import argparse
import math
import os
import sys
import tempfile
from collections import Counter
from pathlib import Path

TABLE = 0.56  # table width, corner to corner, over the girdle diameter
CROWN_ANGLE = 34.5  # degrees between the bezel facets and the girdle plane
PAVILION_ANGLE = 40.75  # degrees between the pavilion mains and the girdle plane
GIRDLE = 0.025  # girdle height halfway between facet junctions (1.25% of the diameter)
STAR = 0.50  # star points: this fraction of the way from the table edge to the girdle
LOWER_HALF = 0.77  # lower-girdle points: this fraction of the way from girdle to culet
DEFAULT_OUT = Path(__file__).resolve().parent.parent / "assets" / "brilliant.obj"


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def polar(r, degrees, y):
    """Point at radius r, azimuth counter-clockwise seen from above (+y), height y."""
    a = math.radians(degrees)
    return (r * math.cos(a), y, -r * math.sin(a))


def cut(a, sector, y0, degrees):
    """Height at radius 1 and azimuth `degrees` of the upper/lower-girdle facet with apex a that
    meets the girdle at height y0 at the junctions bounding the 22.5° sector number `sector`."""
    (x, _, z), b = polar(1, degrees, 0), polar(1, sector * 22.5, y0)
    nx, ny, nz = cross(sub(b, a), sub(polar(1, (sector + 1) * 22.5, y0), a))
    return a[1] - (nx * (x - a[0]) + nz * (z - a[2])) / ny


def build(n):
    """Vertices and facets (group, vertex indices counter-clockwise seen from outside)."""
    verts, facets = [], []

    def add(p):
        verts.append(p)
        return len(verts) - 1

    tc, tp = math.tan(math.radians(CROWN_ANGLE)), math.tan(math.radians(PAVILION_ANGLE))
    c = math.cos(math.radians(22.5))  # star/lower points sit on edges 22.5° off a kite's axis
    # A point on a kite's side edge lies on the kite's plane, through the table corner (culet)
    # and the girdle junction on the kite's axis, level across that axis: heights at radius r.
    rs, rl = TABLE * c + STAR * (1 - TABLE * c), 1 - LOWER_HALF  # radii of star/lower points
    on_bezel = lambda r, yt: yt + (1 - r * c) * tc
    on_main = lambda r, yb: yb - tp + r * c * tp
    # The upper/lower-girdle facets cut deepest into the girdle halfway between junctions:
    # make the girdle GIRDLE thick there (for any n, so the facets do not depend on n).
    drop = -cut(polar(rs, 22.5, on_bezel(rs, 0)), 0, 0, 11.25)
    rise = cut(polar(rl, 22.5, on_main(rl, 0)), 0, 0, 11.25)
    yt = (GIRDLE + drop + rise) / 2
    yb = -yt
    y_table, y_culet = yt + (1 - TABLE) * tc, yb - tp
    table = [add(polar(TABLE, 45 * k, y_table)) for k in range(8)]
    star = [add(polar(rs, 45 * k + 22.5, on_bezel(rs, yt))) for k in range(8)]
    lower = [add(polar(rl, 45 * k + 22.5, on_main(rl, yb))) for k in range(8)]
    culet = add((0.0, y_culet, 0.0))
    m, step = n // 16, 360 / n  # girdle sides per upper/lower-girdle facet, degrees per side

    def girdle_vertex(i, apexes, y0):
        sector, j = divmod(i, m)
        x, _, z = polar(1, i * step, 0)
        y = y0 if j == 0 else cut(verts[apexes[sector // 2]], sector, y0, i * step)
        return add((x, y, z))

    top = [girdle_vertex(i, star, yt) for i in range(n)]
    bot = [girdle_vertex(i, lower, yb) for i in range(n)]
    facets.append(("table", table))
    for k in range(8):
        facets.append(("star", [table[k], star[k], table[(k + 1) % 8]]))
        facets.append(("bezel", [table[k], star[k - 1], top[2 * k * m], star[k]]))
        facets.append(("pavilion main", [culet, lower[k], bot[2 * k * m], lower[k - 1]]))
    for s in range(16):
        span = [(s * m + j) % n for j in range(m + 1)]
        facets.append(("upper girdle", [star[s // 2]] + [top[i] for i in span]))
        facets.append(("lower girdle", [lower[s // 2]] + [bot[i] for i in reversed(span)]))
    for i in range(n):
        j = (i + 1) % n
        facets.append(("girdle", [bot[i], bot[j], top[j], top[i]]))
    thick = [verts[t][1] - verts[b][1] for t, b in zip(top, bot)]
    info = {"crown": (y_table - yt) / 2, "pavilion": (yb - y_culet) / 2,
            "depth": (y_table - y_culet) / 2, "girdle": (min(thick) / 2, max(thick) / 2)}
    return verts, facets, info


def triangles(facets):
    return [(f[0], f[i], f[i + 1]) for _, f in facets for i in range(1, len(f) - 1)]


def obj_text(verts, facets, info, n):
    tris, counts = triangles(facets), Counter(g for g, _ in facets)
    crown = sum(counts[g] for g in ("table", "star", "bezel", "upper girdle"))
    pct = lambda x: f"{100 * x:.2f}%"
    g0, g1 = info["girdle"]
    head = [
        "Round brilliant cut, generated by scripts/brilliant-mesh.py (do not edit; regenerate with",
        f"  python3 scripts/brilliant-mesh.py --girdle-sides {n} --force).",
        f"Proportions: Tolkowsky's 1919 angles with a modern {TABLE:.0%} table: table {TABLE:.0%} "
        "(corner to corner),",
        f"  crown angle {CROWN_ANGLE} deg, pavilion angle {PAVILION_ANGLE} deg, star length "
        f"{STAR:.0%}, lower-girdle length {LOWER_HALF:.0%},",
        f"  pointed culet. Crown height {pct(info['crown'])}, pavilion depth "
        f"{pct(info['pavilion'])}, total depth {pct(info['depth'])}, girdle",
        f"  {pct(g0)} (halfway between facet junctions) to {pct(g1)} (at them) of the diameter.",
        f"Facets: {len(facets)} = crown {crown} + pavilion {len(facets) - crown - n} + girdle {n}",
        "  (" + ", ".join(f"{g} {k}" for g, k in counts.items()) + ").",
        f"Units: girdle radius 1 (girdle {2 * g0:.4f} to {2 * g1:.4f} thick); y up, table "
        "towards +y,", "  girdle centred at the origin.",
        f"{len(verts)} vertices, {len(tris)} triangles; closed, counter-clockwise seen from "
        "outside (outward normals).",
    ]
    fmt = lambda x: f"{round(x, 9) + 0.0:.9f}"  # + 0.0: no "-0.000000000"
    lines = ["# " + h for h in head]
    lines += ["v " + " ".join(fmt(x) for x in v) for v in verts]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in tris]
    return "\n".join(lines) + "\n"


def check(text, facets, info):
    """Verifies the mesh as written in `text`; returns True when every test passes."""
    verts, tris = [], []
    for w in (line.split() for line in text.splitlines()):
        if w and w[0] == "v":
            verts.append(tuple(float(x) for x in w[1:4]))
        elif w and w[0] == "f":
            tris.append(tuple(int(x) - 1 for x in w[1:]))
    failed = []

    def expect(ok, what):
        print(("ok    " if ok else "FAIL  ") + what)
        failed.extend([] if ok else [what])

    expect(all(len(set(t)) == len(t) == 3 for t in tris), "triangles of 3 distinct vertices")
    used = {i for t in tris for i in t}
    expect(used == set(range(len(verts))), f"all {len(verts)} vertices used")
    expect(len(set(verts)) == len(verts), "each position stored once")
    directed = Counter((t[i], t[(i + 1) % 3]) for t in tris for i in range(3))
    repeated = sum(c > 1 for c in directed.values())
    unpaired = sum((b, a) not in directed for a, b in directed)
    expect(repeated == unpaired == 0, "watertight: every edge in exactly two triangles, opposite "
           f"ways ({repeated} directed edges repeated, {unpaired} unpaired)")
    v, e, f = len(verts), len(directed) // 2, len(tris)
    expect(v - e + f == 2, f"Euler characteristic V - E + F = {v} - {e} + {f} = {v - e + f}")
    areas = [math.sqrt(dot(x, x)) / 2 for x in
             (cross(sub(verts[b], verts[a]), sub(verts[c], verts[a])) for a, b, c in tris)]
    expect(min(areas) > 1e-7, f"no degenerate triangles (smallest area {min(areas):.3g})")
    volume = sum(dot(verts[a], cross(verts[b], verts[c])) for a, b, c in tris) / 6
    expect(volume > 0, f"outward orientation: signed volume {volume:.6f} > 0")
    # Per facet: Newell normal, largest distance of its vertices from its plane, and how far
    # any mesh vertex lies outside that plane (0 for a convex solid).
    groups, outside = {}, 0.0
    for g, facet in facets:
        p = [verts[i] for i in facet]
        nrm = [sum(cross(a, b)[k] for a, b in zip(p, p[1:] + p[:1])) for k in range(3)]
        nrm = [x / math.sqrt(dot(nrm, nrm)) for x in nrm]
        ctr = [sum(q[k] for q in p) / len(p) for k in range(3)]
        dev = max(abs(dot(sub(q, ctr), nrm)) for q in p)
        outside = max(outside, max(dot(sub(q, ctr), nrm) for q in verts))
        tilt = round(math.degrees(math.acos(min(1.0, abs(nrm[1])))), 2)
        count, worst, tilts = groups.get(g, (0, 0.0, set()))
        groups[g] = (count + 1, max(worst, dev), tilts | {tilt})
    expect(max(w for _, w, _ in groups.values()) < 1e-7, "every facet planar (limit 1e-7)")
    expect(outside < 1e-7, f"convex: no vertex outside any facet plane (worst {outside:.2g})")
    print(f"\n{v} vertices, {f} triangles, {len(facets)} facets, volume {volume:.6f}")
    print(f"{'facet group':<14} count  angle to girdle plane  max planarity deviation")
    for g, (count, worst, tilts) in groups.items():
        angle = "/".join(f"{t:g}" for t in sorted(tilts)) + " deg"
        print(f"{g:<14} {count:>5}  {angle:>21}  {worst:.2g}")
    pct = lambda x: f"{100 * x:.2f}%"
    print(f"crown height {pct(info['crown'])}, pavilion depth {pct(info['pavilion'])}, total depth "
          f"{pct(info['depth'])}, girdle {pct(info['girdle'][0])}-{pct(info['girdle'][1])} "
          "of the girdle diameter")
    return not failed


def write(path, text, force):
    """Writes through a temporary file in the same directory, renamed into place."""
    if os.path.lexists(path) and not force:
        sys.exit(f"error: {path} exists; pass --force to replace it")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="ascii", newline="\n") as f:
            f.write(text)
        os.chmod(tmp, 0o644)  # mkstemp makes it 0600
        if force:
            os.replace(tmp, path)
        else:
            os.link(tmp, path)  # unlike a rename, fails if the file appeared meanwhile
    except FileExistsError:
        sys.exit(f"error: {path} appeared while writing; pass --force to replace it")
    except OSError as e:
        sys.exit(f"error: cannot write {path}: {e}")
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def main():
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output (default: %(default)s)")
    ap.add_argument("--girdle-sides", type=int, default=32, metavar="N",
                    help="sides of the girdle, a multiple of 16 from 16 to 1024 (default 32)")
    ap.add_argument("--force", action="store_true", help="replace an existing output file")
    ap.add_argument("--check", action="store_true", help="verify the mesh instead of writing it")
    args = ap.parse_args()
    n = args.girdle_sides
    if n < 16 or n > 1024 or n % 16:
        ap.error(f"--girdle-sides must be a multiple of 16 from 16 to 1024 (the 16 facet "
                 f"junctions are girdle vertices), got {n}")
    verts, facets, info = build(n)
    text = obj_text(verts, facets, info, n)
    if not args.check:
        write(args.out, text, args.force)
        print(f"wrote {args.out}: {len(verts)} vertices, {len(triangles(facets))} triangles")
        return
    print(f"round brilliant, {n}-sided girdle")
    ok = check(text, facets, info)
    if args.out.is_file():
        same = args.out.read_text(encoding="ascii", errors="replace") == text
        print(f"{args.out} {'matches this output' if same else 'differs from this output'}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
