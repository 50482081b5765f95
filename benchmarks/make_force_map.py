"""A synthetic JPK force map (``.jpk-force-map``) of the shell model, N x N curves, for the
force-map benchmark of ``benchmarks/commands.py`` (issue 46) and for trying ``shellbvp fit`` on a
map as a user would (issue 45).

The file is a JPK archive as afmformats reads it: a zip of Java property files and, per curve
and segment (extend, retract), big-endian int32 channels (``height``, ``capacitiveSensorHeight``,
``vDeflection``) with the linear encoders and calibrations of the property files.  Those property
files are afmformats' 2 x 2 test map's (``tests/data/fmt-jpk-fd_map2x2_extracted.jpk-force-map``,
https://github.com/AFM-analysis/afmformats, MIT licence), kept in ``benchmarks/data/jpk_force_map``;
the grid, the positions and the number of points are rewritten, the channels written anew.  Its
spring constant (0.0155 N/m) and deflection encoder (int32 up to ~12 nN) set the force scale: the
default sample is a soft cell-like shell (R_L = 10 um, mu*H 0.4 .. 0.8 mN/m, forces up to ~9 nN).

Every pixel is the model curve of ``--preset`` (default ``fit``) at the pixel's mu*H (a smooth
gradient from ``--mu-low`` to ``--mu-high`` over the map), 1 % force noise (seeded), contact at
0.3 um; the tip's depth goes 0 .. 0.35 R_L and back; the height is the depth's negative less the
cantilever's deflection (force / spring constant), so that afmformats' tip position
(height + force / k) is minus the depth.  The truth (mu*H per pixel) goes to ``<out>.truth.npy``.

With ``--thickness LOW,HIGH`` (um) every pixel's shell has its own thickness (thicker towards the
middle, 8 levels), its curve computed with its own scene, and the pixel table for ``shellbvp fit
--pixel-table`` goes to ``<out>.thickness.csv``.

    python benchmarks/make_force_map.py map.jpk-force-map [--n 16] [--points 500] [--thickness 0.3,1.0]
"""

from __future__ import annotations

import argparse
import re
import sys
import zipfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TEMPLATE = HERE / "data" / "jpk_force_map"
#: The channels written, with the calibration slot afmformats reads each in
CHANNELS = {"height": "calibrated", "vDeflection": "force", "capacitiveSensorHeight": "nominal"}
R_L = 10e-6        # m
CONTACT = 0.3e-6   # m: the depth at which the tip touches
TOP = 0.35         # deepest depth / R_L


def properties(text) -> dict:
    """``key=value`` lines of a Java property file (numbers and names only are read here)."""
    out = {}
    for line in text.splitlines():
        if line and not line.startswith("#") and "=" in line:
            key, _, value = line.partition("=")
            out[key.strip()] = value.strip()
    return out


def edit(text, values=None, drop=()):
    """A property file with ``values`` set (existing keys only) and keys starting with ``drop`` removed."""
    values = dict(values or {})
    lines = []
    for line in text.splitlines():
        key = line.partition("=")[0].strip()
        if any(key.startswith(d) for d in drop):
            continue
        if key in values:
            line = f"{key}={values.pop(key)}"
        lines.append(line)
    if values:
        raise KeyError(f"not in the template: {sorted(values)}")
    return "\n".join(lines) + "\n"


def calibration(shared: dict, channel: str, slot: str):
    """``(a, b)``: the value in ``slot`` is ``a * raw + b`` for the int32 ``raw`` of ``channel``."""
    i = next(k.split(".")[1] for k, v in shared.items() if k.endswith(".channel.name") and v == channel)
    p = f"lcd-info.{i}."
    a, b = float(shared[p + "encoder.scaling.multiplier"]), float(shared[p + "encoder.scaling.offset"])
    base = shared[p + "conversion-set.conversions.base"]
    chain = []
    while slot != base:
        q = f"{p}conversion-set.conversion.{slot}."
        chain.append((float(shared[q + "scaling.multiplier"]), float(shared[q + "scaling.offset"])))
        slot = shared[q + "base-calibration-slot"]
    for m, o in reversed(chain):  # from the encoder's unit up to the slot
        a, b = a * m, b * m + o
    return a, b


def encode(values, ab, what):
    a, b = ab
    raw = np.round((np.asarray(values, float) - b) / a)
    if raw.min() < -2**31 or raw.max() >= 2**31:
        raise ValueError(f"{what} outside the int32 range of the template's encoder: reduce the force or depth")
    return raw.astype(">i4").tobytes()


def model_curves(mu_h, points, preset="fit", seed=3, thickness=None):
    """(depth (m), force (N)) of every pixel: the model's curve at its mu*H, approach then retract.
    ``thickness`` (m, an array like ``mu_h``): each pixel's curve is its own scene's, the preset at
    that thickness (one curve computed per distinct value)."""
    from scipy.interpolate import PchipInterpolator

    import shellbvp as sb

    def shape_of(H):
        scene = sb.Scene.preset(preset) if H is None else sb.Scene.preset(preset, thickness=H / R_L)
        c = sb.curve(scene, deltas=np.linspace(0.005, TOP, 120), estimate_error=False)
        if c.delta[-1] < TOP * (1 - 1e-9):
            raise ValueError(f"the model curve at thickness {H} m ends at delta = {c.delta[-1]:.3g} ({c.stop_reason})")
        return PchipInterpolator(np.r_[0, c.delta], np.r_[0, c.force])

    shapes = {}
    pixel_h = [None] * mu_h.size if thickness is None else [float(h) for h in np.ravel(thickness)]
    for H in pixel_h:
        if H not in shapes:
            shapes[H] = shape_of(H)
    top = CONTACT + TOP * R_L
    depth = np.r_[np.linspace(0, top, points), np.linspace(top, 0, points)]
    x = np.clip((depth - CONTACT) / R_L, 0, TOP)
    rng = np.random.default_rng(seed)
    return depth, [m * R_L * shapes[H](x) * (1 + 0.01 * rng.standard_normal(depth.size))
                   for m, H in zip(mu_h.ravel(), pixel_h)]


def thickness_pattern(n, low=0.3e-6, high=1.0e-6, levels=8):
    """(n, n) thickness (m) [iy, ix]: thicker towards the middle of the map (a cell's dome), in
    ``levels`` steps from ``low`` to ``high``."""
    iy, ix = np.mgrid[0:n, 0:n]
    c = (n - 1) / 2
    r = np.hypot(ix - c, iy - c) / max(np.hypot(c, c), 1e-12)
    step = np.round((1 - r) * (levels - 1)) / max(levels - 1, 1)
    return low + (high - low) * step


def write_thickness_table(path, thickness):
    """The pixel table of ``shellbvp fit --pixel-table``: ix, iy, thickness (um)."""
    ny, nx = thickness.shape
    rows = [f"{ix},{iy},{thickness[iy, ix] * 1e6:.9g}" for iy in range(ny) for ix in range(nx)]
    Path(path).write_text("\n".join(["ix,iy,thickness_um", *rows]) + "\n")


def write_map(out, n=16, points=500, mu_low=0.4e-3, mu_high=0.8e-3, preset="fit", pitch=2e-6, thickness=None):
    """Write the N x N map to ``out``; returns the truth, mu*H (N/m) as an (n, n) array [iy, ix].
    ``thickness``: (n, n) array (m) of each pixel's shell thickness (its curve from its own scene);
    None: the preset's geometry everywhere."""
    tpl = {name: (TEMPLATE / name).read_text(encoding="latin-1") for name in
           ("header.properties", "shared-data-header.properties", "index-header.properties",
            "segment-0-header.properties", "segment-1-header.properties")}
    shared = properties(tpl["shared-data-header.properties"])
    cal = {ch: calibration(shared, ch, slot) for ch, slot in CHANNELS.items()}
    k = float(next(v for key, v in shared.items() if re.fullmatch(r"lcd-info\.\d+\.conversion-set\.conversion\."
                                                                  r"force\.scaling\.multiplier", key)))
    iy, ix = np.mgrid[0:n, 0:n]
    mu_h = mu_low + (mu_high - mu_low) * (0.6 * ix + 0.4 * iy) / max(1, n - 1)
    depth, forces = model_curves(mu_h, points, preset, thickness=thickness)
    cx, cy = 0.0, 0.0
    size = pitch * n
    general = edit(tpl["header.properties"], {
        "force-scan-map.indexes.max": str(n * n - 1),
        "force-scan-map.position-pattern.back-and-forth": "false",
        "force-scan-map.position-pattern.grid.xcenter": repr(cx),
        "force-scan-map.position-pattern.grid.ycenter": repr(cy),
        "force-scan-map.position-pattern.grid.ulength": repr(size),
        "force-scan-map.position-pattern.grid.vlength": repr(size),
        "force-scan-map.position-pattern.grid.ilength": str(n),
        "force-scan-map.position-pattern.grid.jlength": str(n)})
    drop = tuple(f"channel.{c}." for c in ("hDeflection", "error"))
    seconds = 1.0  # per segment
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as z:
        folders = set()

        def put(name, data):  # afmformats finds the curves by the archive's folder entries
            parts = name.split("/")[:-1]
            for i in range(1, len(parts) + 1):
                folder = "/".join(parts[:i]) + "/"
                if folder not in folders:
                    folders.add(folder)
                    z.writestr(folder, b"")
            z.writestr(name, data)

        put("header.properties", general)
        put("shared-data/header.properties", tpl["shared-data-header.properties"])
        for e, force in enumerate(forces):
            jx, jy = e % n, e // n
            x, y = cx - size / 2 + (jx + 0.5) * pitch, cy - size / 2 + (jy + 0.5) * pitch
            put(f"index/{e}/header.properties", edit(tpl["index-header.properties"], {
                "force-scan-series.header.position.x": repr(x), "force-scan-series.header.position.y": repr(y),
                "force-scan-series.header.position-index": str(e)}))
            height = 20e-6 - depth - force / k
            for s, rows in enumerate((slice(0, points), slice(points, 2 * points))):
                where = f"index/{e}/segments/{s}/"
                head = {"force-segment-header.num-points": str(points),
                        "force-segment-header.duration": repr(seconds),
                        "channels.list": " ".join(CHANNELS),
                        "force-segment-header.environment.xy-scanner-position-map.xy-scanner.motorstage.position.x":
                            repr(x),
                        "force-segment-header.environment.xy-scanner-position-map.xy-scanner.motorstage.position.y":
                            repr(y),
                        **{f"channel.{c}.data.num-points": str(points) for c in CHANNELS}}
                put(where + "segment-header.properties",
                           edit(tpl[f"segment-{s}-header.properties"], head, drop))
                signal = {"height": height[rows], "capacitiveSensorHeight": height[rows], "vDeflection": force[rows]}
                for c in CHANNELS:
                    put(f"{where}channels/{c}.dat", encode(signal[c], cal[c], f"curve {e}: {c}"))
    return mu_h


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="the .jpk-force-map to write")
    ap.add_argument("--n", type=int, default=16, help="curves per side (default 16: 256 curves)")
    ap.add_argument("--points", type=int, default=500, help="points per segment (default 500)")
    ap.add_argument("--preset", default="fit", help="the model's scene (default fit)")
    ap.add_argument("--thickness", metavar="LOW,HIGH",
                    help="a shell thickness per pixel in um (e.g. 0.3,1.0: thicker towards the middle, 8 levels); "
                         "the pixel table goes to <out>.thickness.csv (shellbvp fit --pixel-table)")
    args = ap.parse_args(argv)
    if not str(args.out).endswith(".jpk-force-map"):
        raise SystemExit("the output must end in .jpk-force-map")
    thickness = None
    if args.thickness:
        low, high = (float(v) * 1e-6 for v in args.thickness.split(","))
        thickness = thickness_pattern(args.n, low, high)
    truth = write_map(args.out, n=args.n, points=args.points, preset=args.preset, thickness=thickness)
    np.save(f"{args.out}.truth.npy", truth)
    if thickness is not None:
        write_thickness_table(f"{args.out}.thickness.csv", thickness)
        print(f"wrote {args.out}.thickness.csv: thickness {thickness.min() * 1e6:.3g} .. {thickness.max() * 1e6:.3g} um")
    print(f"wrote {args.out}: {args.n} x {args.n} curves of {args.points} + {args.points} points, "
          f"mu*H {truth.min() * 1e3:.3g} .. {truth.max() * 1e3:.3g} mN/m, R_L = {R_L * 1e6:g} um "
          f"(preset {args.preset}); truth in {args.out}.truth.npy")


if __name__ == "__main__":
    sys.exit(main())
